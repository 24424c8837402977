"""Fixtures: simulated Ergo Jr robots (ideal servos) to lead and follow."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from poppy_core.robot import Robot
from tests.helpers.robots import sim_ergo_jr as ergo_jr


@pytest.fixture
def leader() -> Iterator[Robot]:
    """A simulated Ergo Jr moved by a test hand."""
    with ergo_jr() as robot:
        yield robot


@pytest.fixture
def follower() -> Iterator[Robot]:
    """A simulated Ergo Jr that follows."""
    with ergo_jr() as robot:
        yield robot
