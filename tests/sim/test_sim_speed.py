"""A simulated motor's present speed is its mean velocity: steady and of the right sign during a
goto (the joint's instantaneous velocity jitters with each goal step)."""

from __future__ import annotations

import time

import pytest

pytest.importorskip("mujoco")


def test_the_present_speed_during_a_goto_follows_the_goto() -> None:
    # Sampled, the joint's velocity read -171 °/s, 319 °/s and 0 on a goto going up at 30-60
    # °/s: the page's speed column jumped about.
    from poppy_core import from_profile

    with from_profile("ergo-jr", sim="mujoco", sensors=False) as robot:
        robot.compliant = False
        robot.goto_position({"m1": 0.0}, 0.5, wait=True)
        robot.goto_position({"m1": 60.0}, 6.0, wait=False)  # min-jerk: 10 °/s mean, 19 peak
        speeds = []
        # the middle of the goto, 10° to 40° (about 2 s), sampled by position, not by the clock:
        # a busy machine may run this thread late
        while (position := robot.m1.present_position) < 40.0:
            if position > 10.0:
                speeds.append(robot.m1.present_speed)
            time.sleep(0.02)
        assert len(speeds) >= 5
        assert all(0.0 < speed < 200.0 for speed in speeds), speeds  # a busy machine: faster
