"""``GoalStream``: the start ramp, goals written at once, hold, resume, the watchdog."""

from __future__ import annotations

import time

import pytest
from hypothesis import given
from hypothesis import strategies as st

from poppy_core.errors import ArgumentError, ConfigError, UnknownMotorError
from poppy_core.motion.teleop.goal_stream import GoalStream
from poppy_core.robot import Robot
from poppy_core.trajectory import minimum_jerk_weight
from tests.teleop.hands import READ_S, Hand, wait_for


class Clock:
    """A clock the test moves by hand."""

    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


@given(st.floats(0.0, 1.0), st.floats(0.0, 1.0))
def test_minimum_jerk_weight_goes_from_0_to_1_without_going_back(a: float, b: float) -> None:
    assert minimum_jerk_weight(0.0) == 0.0 and minimum_jerk_weight(1.0) == 1.0
    low, high = sorted((a, b))
    assert 0.0 <= minimum_jerk_weight(low) <= minimum_jerk_weight(high) <= 1.0
    assert minimum_jerk_weight(-1.0) == 0.0 and minimum_jerk_weight(2.0) == 1.0


def test_start_ramps_from_where_the_follower_is_to_the_moving_target(follower: Robot) -> None:
    hand = Hand(follower)
    hand.put({"m1": 10.0, "m2": -20.0})
    time.sleep(READ_S)
    clock = Clock()
    session = GoalStream(follower, ["m1", "m2"], ramp_s=1.0, clock=clock)
    session.start()
    assert session.state == "held" and not follower.m1.compliant
    first = session.push({"m1": 60.0, "m2": 20.0})
    assert session.state == "ramping"
    assert first["m1"] == pytest.approx(10.0, abs=0.5)  # no jump toward the target
    assert first["m2"] == pytest.approx(-20.0, abs=0.5)
    clock.now += 0.5
    half = session.push({"m1": 60.0, "m2": 20.0})
    assert half["m1"] == pytest.approx(35.0, abs=0.5)  # the minimum-jerk midpoint
    clock.now += 0.25
    moving = session.push({"m1": 80.0, "m2": 20.0})  # the target moves during the ramp
    assert 35.0 < moving["m1"] < 80.0
    clock.now += 0.3
    done = session.push({"m1": 80.0, "m2": 20.0})
    assert session.state == "following" and done["m1"] == pytest.approx(80.0, abs=0.3)
    # sent to the servos at once (the emulator's thread handles the bytes a moment later);
    # indirect m2: the motor frame has the other sign
    assert wait_for(lambda: hand.goal("m1") == pytest.approx(80.0, abs=0.3), timeout_s=1.0)
    assert hand.goal_motor_frame("m2") == pytest.approx(-20.0, abs=0.3)


def test_automatic_ramp_lasts_by_distance_and_none_when_already_there(follower: Robot) -> None:
    clock = Clock()
    session = GoalStream(follower, ["m1"], clock=clock)
    session.start()
    session.push({"m1": 0.2})
    assert session.state == "following" and session.ramps == 0
    session.hold("test")
    session.push({"m1": 60.0})  # 60° at 60°/s: a 1 s ramp
    assert session.state == "ramping"
    clock.now += 0.9
    session.push({"m1": 60.0})
    assert session.state == "ramping"
    clock.now += 0.2
    session.push({"m1": 60.0})
    assert session.state == "following" and session.ramps == 1


def test_hold_stops_where_the_motors_are_and_the_next_target_ramps(follower: Robot) -> None:
    hand = Hand(follower)
    clock = Clock()
    changes: list[str] = []
    session = GoalStream(
        follower, ["m1"], ramp_s=0.5, on_change=lambda c: changes.append(c.state), clock=clock
    )
    session.start()
    session.push({"m1": 0.0})
    clock.now += 1.0
    session.push({"m1": 30.0})  # following: the servo goes there
    assert wait_for(lambda: follower.m1.present_position == pytest.approx(30.0, abs=0.5))
    session.hold("link lost")
    assert session.state == "held" and session.holds == 1
    assert follower.m1.goal_position == pytest.approx(follower.m1.present_position, abs=0.5)
    assert wait_for(lambda: hand.goal("m1") == pytest.approx(30.0, abs=0.5), timeout_s=1.0)
    again = session.push({"m1": -40.0})  # far away: resumes with a ramp, no jump
    assert session.state == "ramping" and again["m1"] == pytest.approx(30.0, abs=1.0)
    assert changes == ["held", "following", "held", "ramping"]


def test_watchdog_expires_only_while_the_stream_runs() -> None:
    clock = Clock()
    session = GoalStream(_robot_with_m1(), ["m1"], watchdog_s=0.25, write_now=False, clock=clock)
    assert not session.expired()
    session.push({"m1": 0.0})  # a motor never read: already there, following
    assert session.state == "following"
    clock.now += 0.2
    assert not session.expired()
    clock.now += 0.1
    assert session.expired()
    session.hold("watchdog")
    assert not session.expired()


def _robot_with_m1() -> Robot:
    from poppy_core.models import model_by_name
    from poppy_core.robot import Motor

    return Robot([Motor("m1", model_by_name("XL-320"), 1)])


def test_unknown_motors_are_refused_and_a_stopped_session_takes_nothing(follower: Robot) -> None:
    with pytest.raises(ConfigError, match="no motor 'm9'"):
        GoalStream(follower, ["m1", "m9"])
    with pytest.raises(ArgumentError, match="no motor to follow"):
        GoalStream(follower, [])
    session = GoalStream(follower, ["m1"], ramp_s=0.0)
    session.start()
    with pytest.raises(UnknownMotorError, match="not followed: m2"):
        session.push({"m2": 1.0})
    session.push({"m1": 20.0})
    session.stop()
    assert session.state == "stopped"
    assert session.push({"m1": -50.0})["m1"] != -50.0
