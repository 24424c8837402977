"""Fixtures of the creature tests: one simulated creature per module."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from poppy_core import from_profile
from poppy_core.robot import Robot
from tests.helpers.fixtures import ergo_fixture

ergo = ergo_fixture(scope="module")
"""One simulated Ergo Jr per module."""


@pytest.fixture(scope="module")
def humanoid() -> Iterator[Robot]:
    """One simulated Humanoid (25 motors, 2 buses) per module."""
    with from_profile("humanoid", sim=True) as robot:
        yield robot
