"""Fixtures of the kinematics tests: the creatures' chains built from their profiles."""

from __future__ import annotations

import pytest

from poppy_core.kinematics import Chain
from poppy_core.motion.chains import chains_from_config
from poppy_core.robot import load_profile


@pytest.fixture(scope="session")
def creature_chains() -> dict[str, dict[str, Chain]]:
    """Creature -> chain name -> chain, from the installed profiles."""
    return {
        kind: chains_from_config(load_profile(kind)) for kind in ("ergo-jr", "torso", "humanoid")
    }


@pytest.fixture(scope="session")
def ergo_chain(creature_chains: dict[str, dict[str, Chain]]) -> Chain:
    """The Ergo Jr's ``chain``."""
    return creature_chains["ergo-jr"]["chain"]
