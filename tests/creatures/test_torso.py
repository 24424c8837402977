"""Poppy Torso on the emulator: its behaviours are the Humanoid's upper-body ones."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from poppy_core import from_profile
from poppy_core.robot import Robot
from tests.creatures.helpers import positions, wait_until
from tests.helpers.pypot_names import TORSO_PRIMITIVES


@pytest.fixture(scope="module")
def torso() -> Iterator[Robot]:
    """One simulated Torso per module."""
    with from_profile("torso", sim=True) as robot:
        yield robot


def test_behaviours_are_attached(torso: Robot) -> None:
    assert torso.creature.kind == "torso" and torso.creature.goto_control == "minjerk"
    assert torso.primitive_names == TORSO_PRIMITIVES
    assert "stand_position" not in torso.extensions  # no legs
    assert torso.active_primitives == [torso.temperature_monitoring]
    assert all(m.compliant_behavior == "safe" for m in torso.torso)
    assert torso.head_z.compliant_behavior == "dummy"


def test_dance_beat_motion_follows_its_bpm(torso: Robot) -> None:
    torso.compliant = False
    beat = torso.dance_beat_motion
    beat.bpm = 120.0  # a nod every 0.5 s, a sway every second
    beat.amplitude = 12.0
    beat.start()
    try:
        assert wait_until(lambda: "head_y" in beat.offsets(0.0), 1.0)  # set up
        offsets = beat.offsets(0.125)  # an eighth of a second: a quarter of a nod
        assert offsets["head_y"] == pytest.approx(6.0)
        assert set(offsets) == {"head_y", "head_z", "bust_x", "abs_z"}
        start = positions(torso, ["head_z", "bust_x"])
        assert wait_until(
            lambda: all(abs(torso.motor(n).present_position - v) > 3 for n, v in start.items()),
            2.0,
        )
    finally:
        beat.stop()
    assert beat.state == "stopped" and beat.error is None


def test_start_defaults_can_be_turned_off() -> None:
    with from_profile("torso", sim=True, start_defaults=False) as robot:
        assert robot.temperature_monitoring.state == "idle"
        assert robot.active_primitives == []
    assert robot.temperature_monitoring.state in ("idle", "stopped")
