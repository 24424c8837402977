"""Chains on robots: pypot's IKChain API over the motors, synchronised gotos, straight moves."""

from __future__ import annotations

import time

import numpy as np
import pytest

from poppy_core import from_profile
from poppy_core.errors import KinematicsError
from poppy_core.motion.cartesian import RobotChain
from poppy_core.robot import Robot
from tests.helpers.fixtures import ergo_fixture

SETTLE_S = 0.3


ergo = ergo_fixture(scope="module", stiff=True)


def _settle(robot: Robot) -> None:
    time.sleep(SETTLE_S)


def test_pypot_names(ergo: Robot) -> None:
    chain = ergo.chain
    assert isinstance(chain, RobotChain)
    assert [m.name for m in chain.motors] == ["m1", "m2", "m3", "m4", "m5", "m6"]
    assert chain.motors[0] is ergo.m1
    assert chain.joints_position == [m.present_position for m in chain.motors]
    pose = chain.pose
    assert pose.shape == (4, 4)
    assert np.allclose(chain.position, pose[:3, 3]) and np.allclose(chain.orientation, pose[:3, 0])
    assert np.allclose(chain.rpy_to_rotation_matrix(0.0, 0.0, np.pi / 2) @ [1, 0, 0], [0, 1, 0])


def test_forward_fills_missing_motors_with_present_positions(ergo: Robot) -> None:
    chain = ergo.chain
    present = {m.name: m.present_position for m in chain.motors}
    assert np.allclose(chain.forward({"m1": present["m1"]}), chain.model.forward(present))
    assert np.allclose(chain.forward({"m1": 40.0}), chain.model.forward({**present, "m1": 40.0}))


def test_goto_moves_the_tip_there(ergo: Robot) -> None:
    chain = ergo.chain
    target = chain.forward({"m1": 30.0, "m2": -40.0, "m3": 30.0, "m4": 0.0, "m5": 40.0, "m6": 0.0})
    handle = chain.goto(target[:3, 3], duration=0.5, wait=True)
    assert handle.done and not handle.cancelled
    _settle(ergo)
    assert np.linalg.norm(chain.position - target[:3, 3]) < 0.003


def test_all_motors_arrive_together(ergo: Robot) -> None:
    chain = ergo.chain
    target = chain.forward({"m1": -30.0, "m2": -20.0, "m3": 50.0})[:3, 3]
    handle = chain.goto(target, duration=0.4)
    assert handle.duration_s == 0.4  # one goto handle for every motor of the chain
    assert handle.wait(5.0)


def test_a_number_for_orientation_says_to_name_the_duration(ergo: Robot) -> None:
    with pytest.raises(KinematicsError, match="duration by name"):
        ergo.chain.goto(ergo.chain.position, 0.5)


def test_out_of_reach_goto_moves_nothing(ergo: Robot) -> None:
    goals = {m.name: m.goal_position for m in ergo.motors}
    with pytest.raises(KinematicsError, match="nearest point"):
        ergo.chain.goto([0.0, 0.0, 1.0], duration=0.5)
    assert {m.name: m.goal_position for m in ergo.motors} == goals


def test_solve_respects_limits_changed_at_run_time(ergo: Robot) -> None:
    chain = ergo.chain
    target = chain.model.forward({"m2": -60.0, "m3": 40.0})[:3, 3]
    before = ergo.m2.angle_limit
    try:
        ergo.m2.angle_limit = (-50.0, 125.0)
        angles = chain.solve(target, seed={n: 0.0 for n in chain.model.names})
        assert angles["m2"] >= -50.0
        assert np.linalg.norm(chain.model.forward(angles)[:3, 3] - target) < 1e-3
    finally:
        ergo.m2.angle_limit = before


def test_goto_linear_follows_the_segment(ergo: Robot) -> None:
    chain = ergo.chain
    start_pose = chain.model.forward({"m2": -30.0, "m3": 30.0, "m5": 30.0})
    chain.goto(start_pose[:3, 3], duration=0.4, wait=True)
    _settle(ergo)
    start = chain.position.copy()
    end = start + np.array([0.0, 0.04, -0.03])
    move = chain.goto_linear(end, duration=1.0)
    off_line = []
    while not move.done:
        p = chain.position
        s = np.clip((p - start) @ (end - start) / np.sum((end - start) ** 2), 0.0, 1.0)
        off_line.append(float(np.linalg.norm(p - (start + s * (end - start)))))
        time.sleep(0.05)
    assert move.error is None
    _settle(ergo)
    assert np.linalg.norm(chain.position - end) < 0.003
    assert max(off_line) < 0.005


def test_goto_linear_out_of_reach_moves_nothing(ergo: Robot) -> None:
    goals = {m.name: m.goal_position for m in ergo.motors}
    with pytest.raises(KinematicsError, match="cannot reach"):
        ergo.chain.goto_linear([0.0, 0.0, 0.9], duration=0.5)
    with pytest.raises(KinematicsError, match="straight line"):
        ergo.chain.goto_linear([0.0, 0.15, 0.05], duration=0.5)  # through the base
    assert {m.name: m.goal_position for m in ergo.motors} == goals


def test_arm_chains_of_the_torso_move_only_the_arm() -> None:
    with from_profile("torso", sim=True, start_defaults=False) as torso:
        chain = torso.r_arm_chain
        assert [m.name for m in chain.active_motors] == [m.name for m in torso.r_arm]
        pose = {m.name: m.present_position for m in chain.motors}
        pose.update({"r_shoulder_y": -40.0, "r_elbow_y": 60.0})
        angles = chain.solve(chain.forward(pose)[:3, 3])
        assert set(angles) == {m.name for m in torso.r_arm}


class _BrokenRobot:
    def goto_position(self, *args: object, **kwargs: object) -> None:
        raise RuntimeError("the goto broke")


def test_a_straight_move_that_fails_says_so_to_its_waiter() -> None:
    from poppy_core.motion.straight_line import LinearMove

    move = LinearMove(_BrokenRobot(), [{"m1": 0.0}, {"m1": 1.0}], 0.01, "arm")  # type: ignore[arg-type]
    with pytest.raises(RuntimeError, match="the goto broke"):
        move.wait(timeout_s=5.0)
    assert move.done and isinstance(move.error, RuntimeError)
