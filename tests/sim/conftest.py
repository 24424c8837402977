"""Fixtures of the MuJoCo simulation tests."""

from __future__ import annotations

from collections.abc import Iterator

import pytest
from sim_helpers import World, make_world


@pytest.fixture
def torso() -> Iterator[World]:
    world = make_world("torso")
    yield world
    world.sim.close()


@pytest.fixture
def ergo() -> Iterator[World]:
    world = make_world("ergo-jr")
    yield world
    world.sim.close()
