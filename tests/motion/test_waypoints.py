"""The motion room's trajectory follower: timed points, each set once, the next replacing it."""

from __future__ import annotations

import time
from collections.abc import Iterator

import pytest

from poppy_core import from_profile
from poppy_core.motion.waypoints import WaypointFollower, Waypoints
from poppy_core.robot import Robot
from tests.helpers.waiting import eventually


@pytest.fixture
def robot() -> Iterator[Robot]:
    with from_profile("ergo-jr", sim=True) as jr:
        jr.compliant = False
        yield jr


def test_every_point_is_set_once_even_between_two_periods() -> None:
    plan = Waypoints(("m1",), (0.05, 0.1), ((20.0,), (-10.0,)), 0.0)
    goals, reached = plan.step(0.07, (0.0,), 0)  # the first point's time went by: set it
    assert goals == (20.0,) and reached == 1
    goals, reached = plan.step(0.075, (0.0,), reached)  # then between the two points
    assert goals[0] == pytest.approx(20.0 - 30.0 * 0.5) and reached == 1
    assert plan.step(1.0, (0.0,), reached) == ((-10.0,), 2)  # the last one, then held


def test_the_follower_reaches_the_last_point_and_stops(robot: Robot) -> None:
    follower = WaypointFollower(robot, 50.0)
    try:
        follower.follow(Waypoints(("m1",), (0.2, 0.4), ((15.0,), (-5.0,))))
        assert follower.following
        assert eventually(lambda: not follower.following)
        assert robot.m1.goal_position == pytest.approx(-5.0, abs=0.1)
    finally:
        follower.close()


def test_the_next_waypoints_replace_the_running_ones_and_stop_holds(robot: Robot) -> None:
    follower = WaypointFollower(robot, 50.0)
    try:
        follower.follow(Waypoints(("m1",), (30.0,), ((40.0,),)))
        follower.follow(Waypoints(("m2",), (0.1,), ((-15.0,),)))
        assert eventually(lambda: abs(robot.m2.goal_position + 15.0) < 0.1)
        assert eventually(lambda: not follower.following)
        assert abs(robot.m1.goal_position) < 5.0  # the first one was replaced at once
        follower.follow(Waypoints(("m3",), (30.0,), ((30.0,),)))
        assert follower.stop() and not follower.following
        held = robot.m3.goal_position
        time.sleep(0.1)
        assert robot.m3.goal_position == held
    finally:
        follower.close()


def test_a_motor_made_compliant_ends_the_trajectory(robot: Robot) -> None:
    follower = WaypointFollower(robot, 50.0)
    try:
        follower.follow(Waypoints(("m1",), (30.0,), ((40.0,),)))
        robot.m1.compliant = True
        assert eventually(lambda: not follower.following)
    finally:
        follower.close()
