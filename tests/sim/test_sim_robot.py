"""A robot built with sim="mujoco": the same bytes on a pty, physics behind the servos."""

from __future__ import annotations

import time

import pytest

from poppy_core.errors import ConfigError
from poppy_core.robot.factory import build_plain_robot, profile_config
from tests.helpers.waiting import eventually


def test_ergo_jr_goto_ends_near_the_goal_in_the_physics() -> None:
    with build_plain_robot(profile_config("ergo-jr"), sim="mujoco") as robot:
        simulation = robot.simulation
        assert simulation is not None and simulation.running
        robot.compliant = False
        goal = {"m1": 20.0, "m2": -30.0, "m3": 25.0, "m4": -15.0, "m5": 30.0, "m6": -20.0}
        robot.goto_position(goal, 1.0, wait=True)

        def arrived() -> bool:
            # the joint takes the motor's own angle: m2, m3, m5 and m6 are indirect
            return all(
                abs(simulation.joint_deg(name) - robot.motor(name).to_motor(value)) <= 2.0
                and abs(robot.motor(name).present_position - value) <= 2.0
                for name, value in goal.items()
            )

        assert eventually(arrived), {m.name: m.present_position for m in robot.motors}
    assert not simulation.running  # close() stopped the physics thread


def test_compliant_robot_can_be_moved_by_hand() -> None:
    with build_plain_robot(profile_config("ergo-jr"), sim="mujoco") as robot:
        robot.compliant = True
        time.sleep(0.2)
        bus = next(iter(robot.emulators.values())).bus
        bus.motor(1).move_by_hand(50.0)  # m1: direct, no offset
        assert eventually(lambda: abs(robot.m1.present_position - 50.0) <= 2.0)


def test_ideal_simulation_has_no_handle() -> None:
    with build_plain_robot(profile_config("ergo-jr"), sim=True) as robot:
        assert robot.simulation is None


def test_unknown_simulation_is_refused() -> None:
    with pytest.raises(ConfigError):
        build_plain_robot(profile_config("ergo-jr"), sim="bullet")


def test_humanoid_runs_with_two_buses_on_one_world() -> None:
    with build_plain_robot(profile_config("humanoid"), sim="mujoco") as robot:
        assert len(robot.emulators) == 2
        robot.compliant = False
        robot.goto_position({"head_z": 30.0, "l_knee_y": 20.0}, 0.5, wait=True)
        assert eventually(lambda: abs(robot.simulation.joint_deg("head_z") - 30.0) <= 3.0)
        assert eventually(lambda: abs(robot.head_z.present_position - 30.0) <= 3.0)
