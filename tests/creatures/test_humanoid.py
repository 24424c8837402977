"""Poppy Humanoid on the emulator (25 motors, 2 buses): setup, postures, safety, interactions."""

from __future__ import annotations

import logging
import time

import pytest

from poppy_core.creatures.interaction import ARM_JOINTS
from poppy_core.creatures.postures import humanoid_sit
from poppy_core.motion import primitive_manager
from poppy_core.robot import Robot
from tests.creatures.helpers import positions, reached, stop_all, virtual, wait_until
from tests.helpers.pypot_names import HUMANOID_PRIMITIVES


@pytest.fixture(autouse=True)
def _stiff(humanoid: Robot) -> None:
    """Each test starts stiff, with no primitive left running (but the monitor)."""
    stop_all(humanoid)
    humanoid.compliant = False


def test_behaviours_are_attached_and_the_monitor_runs(humanoid: Robot) -> None:
    assert len(humanoid.motors) == 25 and len(humanoid.buses) == 2
    assert humanoid.primitive_names == HUMANOID_PRIMITIVES
    assert humanoid.creature.kind == "humanoid"
    assert humanoid.creature.goto_control == "minjerk"
    assert humanoid.temperature_monitoring.state == "running"  # started by default
    assert primitive_manager(humanoid).filter([1.0, 2.0]) == 3.0


def test_torso_motors_have_safe_compliance(humanoid: Robot) -> None:
    torso = {m.name for m in humanoid.torso}
    assert torso == {"abs_y", "abs_x", "abs_z", "bust_y", "bust_x"}
    for motor in humanoid.motors:
        assert motor.compliant_behavior == ("safe" if motor.name in torso else "dummy")


def test_sit_then_stand_reach_their_targets(humanoid: Robot) -> None:
    humanoid.sit_position.duration = 0.5
    humanoid.sit_position.start()
    assert humanoid.sit_position.wait_to_stop(5.0)
    sit = humanoid_sit()
    assert sit["l_knee_y"] == sit["r_knee_y"] == 134.0  # pypot's: the same angle on both legs
    assert wait_until(lambda: reached(humanoid, sit), 2.0), positions(humanoid, sit)
    humanoid.stand_position.duration = 0.5
    humanoid.stand_position.start()
    assert humanoid.stand_position.wait_to_stop(5.0)
    assert humanoid.stand_position.error is None
    zeros = {m.name: 0.0 for m in humanoid.motors}
    assert wait_until(lambda: reached(humanoid, zeros), 2.0), positions(humanoid)


def test_temperature_monitoring_warns_about_a_hot_motor(
    humanoid: Robot, caplog: pytest.LogCaptureFixture
) -> None:
    monitor = humanoid.temperature_monitoring
    monitor.update_freq = 10.0
    monitor.player = "true"  # the alarm's sound: played silently
    monitor.start()  # restart at the new rate
    hot = virtual(humanoid, "r_knee_y")  # on the lower body's bus
    with caplog.at_level(logging.WARNING, logger="poppy_core.creatures.safety"):
        hot.table.set_si("present_temperature", 62.0)
        try:
            assert wait_until(lambda: "r_knee_y" in monitor.hot_motors, 4.0)
            assert any(
                "r_knee_y is too hot" in r.getMessage() and "62" in r.getMessage()
                for r in caplog.records
            ), caplog.text
            assert monitor.hot_motors == ["r_knee_y"]
        finally:
            hot.table.set_si("present_temperature", 30.0)
    assert wait_until(lambda: monitor.hot_motors == [], 4.0)


def test_arms_copy_motion_mirrors_the_left_arm_on_the_right(humanoid: Robot) -> None:
    copy = humanoid.arms_copy_motion
    copy.start()
    try:
        left = [virtual(humanoid, m.name) for m in humanoid.l_arm]
        # The primitive sets the left arm compliant from its own thread: wait for both ends.
        assert wait_until(
            lambda: (
                all(m.compliant for m in humanoid.l_arm) and not any(v.torque_enabled for v in left)
            ),
            2.0,
        )
        assert not any(m.compliant for m in humanoid.r_arm)
        moved = {"l_shoulder_x": 30.0, "l_elbow_y": -60.0, "l_shoulder_y": -20.0}
        for name, user_deg in moved.items():
            virtual(humanoid, name).move_by_hand(humanoid.motor(name).to_motor(user_deg))
        assert wait_until(lambda: reached(humanoid, moved, 1.0), 2.0), positions(humanoid, moved)
        # pypot's PuppetMaster: pitches (shoulder_y, elbow_y) copied, roll and yaw negated
        mirrored = {"r_shoulder_x": -30.0, "r_elbow_y": -60.0, "r_shoulder_y": -20.0}
        assert wait_until(lambda: reached(humanoid, mirrored), 3.0), positions(humanoid)
    finally:
        copy.stop()
    assert copy.state == "stopped" and copy.error is None
    assert wait_until(lambda: not any(m.compliant for m in humanoid.l_arm), 2.0)
    assert reached(humanoid, moved, 3.0)  # the left arm holds where the hand left it


def test_arms_turn_compliant_frees_a_pushed_arm(humanoid: Robot) -> None:
    turn = humanoid.arms_turn_compliant
    turn.release_after_s = 0.5
    turn.start()
    pushed = virtual(humanoid, "r_shoulder_x")
    motor = humanoid.r_shoulder_x
    try:
        # A hand holds the arm 30° away from its goal; the ideal plant reports no load, the
        # position error shows the push.
        deadline = time.monotonic() + 3.0
        while not motor.compliant and time.monotonic() < deadline:
            pushed.move_by_hand(motor.to_motor(motor.goal_position + 30.0))
            time.sleep(0.01)
        assert motor.compliant
        assert wait_until(lambda: all(m.compliant for m in humanoid.r_arm), 1.0)
        assert not any(m.compliant for m in humanoid.l_arm)  # the other arm stays stiff
        assert turn.compliant_arms == ["r"]
        # Left alone, the arm stays still and stiffens again where it was put.
        assert wait_until(lambda: not any(m.compliant for m in humanoid.r_arm), 3.0)
        assert turn.compliant_arms == []
    finally:
        turn.stop()
    assert turn.state == "stopped" and turn.error is None


def test_limit_torque_follows_the_distance_to_the_goal(humanoid: Robot) -> None:
    limit = humanoid.limit_torque
    assert limit.torque_for(0.0) == pytest.approx(limit.min_torque)
    assert limit.torque_for(-90.0) == pytest.approx(limit.max_torque)
    before = humanoid.head_z.torque_limit
    limit.start()
    try:
        at_goal = virtual(humanoid, "l_elbow_y")
        assert wait_until(
            lambda: at_goal.table.get_si("torque_limit") == pytest.approx(limit.min_torque, abs=0.5)
        )
        assert all(
            m.torque_limit == pytest.approx(limit.min_torque, abs=2.0) for m in humanoid.motors
        )
    finally:
        limit.stop()
    assert humanoid.head_z.torque_limit == pytest.approx(before)  # given back


def test_upper_body_motions_move_and_stop(humanoid: Robot) -> None:
    beat = humanoid.dance_beat_motion
    beat.set_property("bpm", "120")
    head = humanoid.head_idle_motion
    body = humanoid.upper_body_idle_motion
    for primitive in (beat, head, body):
        primitive.start()
    try:
        watched = ["head_y", "head_z", "bust_x", "abs_z"]
        start = positions(humanoid, watched)
        assert wait_until(
            lambda: all(abs(humanoid.motor(n).present_position - start[n]) > 1.0 for n in watched),
            3.0,
        ), positions(humanoid, watched)
    finally:
        for primitive in (beat, head, body):
            primitive.stop()
    assert all(p.state == "stopped" and p.error is None for p in (beat, head, body))
    assert set(ARM_JOINTS) == {"shoulder_y", "shoulder_x", "arm_z", "elbow_y"}
