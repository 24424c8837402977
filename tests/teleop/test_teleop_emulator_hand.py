"""Teleop without hardware: the emulator's hand moves the leader, the follower follows."""

from __future__ import annotations

from collections.abc import Mapping

import pytest

from poppy_core.emulator import Hand
from poppy_core.motion.teleop.session import teleoperate
from poppy_core.robot import Robot
from tests.helpers.waiting import eventually

ARM = ("m1", "m2", "m3")


def hand_on(robot: Robot) -> Hand:
    """The emulator's hand on every bus of a simulated robot."""
    return Hand(*(server.bus for server in robot.emulators.values()))


def gesture(hand: Hand, robot: Robot, targets: Mapping[str, float], over_s: float) -> None:
    """The hand moves joints to user-frame angles (the servos' own angles for the emulator)."""
    for name, degrees in targets.items():
        motor = robot.motor(name)
        hand.move(motor.id, motor.to_motor(degrees), over_s=over_s)


def near(robot: Robot, targets: Mapping[str, float], tolerance: float = 2.0) -> bool:
    return all(abs(robot.motor(n).present_position - d) <= tolerance for n, d in targets.items())


def test_the_follower_follows_a_leader_moved_by_the_emulators_hand(
    leader: Robot, follower: Robot
) -> None:
    with hand_on(leader) as hand, teleoperate(leader, follower, rate_hz=50) as teleop:
        assert eventually(lambda: teleop.status().state == "following", timeout_s=10.0)
        assert all(leader.motor(m).compliant for m in ARM)
        first = {"m1": 30.0, "m2": -25.0, "m3": 40.0}
        gesture(hand, leader, first, over_s=1.0)
        assert eventually(lambda: near(leader, first) and near(follower, first), timeout_s=15.0)
        then = {"m1": -20.0, "m2": 10.0, "m3": 0.0}
        gesture(hand, leader, then, over_s=0.5)
        assert eventually(lambda: near(follower, then), timeout_s=15.0)
        hand.release()  # a compliant leader stays where the hand left it: so does the follower
        assert near(leader, then) and eventually(lambda: near(follower, then), timeout_s=5.0)
    report = teleop.report()
    assert report.holds == 0


def test_a_stiff_motor_resists_the_hand(leader: Robot) -> None:
    leader.motor("m1").compliant = False
    leader.motor("m1").goal_position = 0.0
    hand = hand_on(leader)
    try:
        gesture(hand, leader, {"m1": 45.0}, over_s=0.3)
        assert hand.wait(10.0)
        assert eventually(lambda: abs(leader.motor("m1").present_load) > 50.0, timeout_s=5.0)
        assert leader.motor("m1").present_position == pytest.approx(0.0, abs=1.0)
    finally:
        hand.close()
