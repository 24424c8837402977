"""The MJCF models: generated from the URDFs, load cleanly, named and signed like the profiles."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
from sim_helpers import PROFILES, ROBOTS

from poppy_core.robot.profiles import load_profile
from poppy_core.sim.mjcf import ROBOTS as URDF_FILES
from poppy_core.sim.mjcf import generate
from poppy_core.sim.urdf import (
    Quat,
    Vec3,
    parse_urdf,
    quat_from_axis_angle,
    quat_from_rpy,
    quat_mul,
    rotate,
)

mujoco = pytest.importorskip("mujoco")


def _model(robot: str) -> Any:
    return mujoco.MjModel.from_xml_path(str(PROFILES / robot / "model.xml"))


@pytest.mark.parametrize("robot", ROBOTS)
def test_committed_model_is_the_generator_output(robot: str) -> None:
    assert (PROFILES / robot / "model.xml").read_text(encoding="utf-8") == generate(robot, PROFILES)


@pytest.mark.parametrize("robot", ROBOTS)
def test_model_loads_and_steps_without_warnings(robot: str) -> None:
    model = _model(robot)
    data = mujoco.MjData(model)
    for _ in range(500):
        mujoco.mj_step(model, data)
    assert [w.number for w in data.warning] == [0] * len(data.warning)
    assert np.all(np.isfinite(data.qpos))


@pytest.mark.parametrize("robot", ROBOTS)
def test_joint_and_actuator_names_are_the_motor_names(robot: str) -> None:
    model = _model(robot)
    hinges = {
        model.joint(i).name
        for i in range(model.njnt)
        if model.jnt_type[i] == mujoco.mjtJoint.mjJNT_HINGE
    }
    actuators = {model.actuator(i).name for i in range(model.nu)}
    motors = set(load_profile(robot).motors)
    assert hinges == motors
    assert actuators == motors


@pytest.mark.parametrize("robot", ROBOTS)
def test_joint_ranges_are_the_profile_angle_limits(robot: str) -> None:
    model = _model(robot)
    for name, entry in load_profile(robot).motors.items():
        low, high = np.degrees(model.joint(name).range)
        assert (low, high) == pytest.approx(tuple(entry.angle_limit), abs=1e-3)


@pytest.mark.parametrize("robot", ["torso", "humanoid"])
def test_standing_robot_stays_up_holding_its_zero_pose(robot: str) -> None:
    model = _model(robot)
    data = mujoco.MjData(model)
    head = model.body("head").id
    mujoco.mj_forward(model, data)
    height = data.xpos[head][2]
    for _ in range(1000):
        mujoco.mj_step(model, data)
    assert data.xpos[head][2] == pytest.approx(height, abs=0.02)


# ---------------------------------------------------------------------- the sign convention


def _urdf_positions(robot: str, urdf_deg: dict[str, float]) -> dict[str, Vec3]:
    """Link origins relative to the root link, for URDF joint angles in degrees."""
    urdf = parse_urdf(PROFILES / robot / URDF_FILES[robot])
    poses: dict[str, tuple[Vec3, Quat]] = {urdf.root: ((0.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0))}
    pending = [urdf.root]
    while pending:
        link = pending.pop()
        pos, quat = poses[link]
        for joint in urdf.children(link):
            offset = rotate(quat, joint.xyz)
            turn = quat_from_axis_angle(joint.axis, math.radians(urdf_deg.get(joint.name, 0.0)))
            child = quat_mul(quat_mul(quat, quat_from_rpy(joint.rpy)), turn)
            poses[joint.child] = (
                (pos[0] + offset[0], pos[1] + offset[1], pos[2] + offset[2]),
                child,
            )
            pending.append(joint.child)
    return {name: pose[0] for name, pose in poses.items()}


def _mujoco_positions(robot: str, poppy_deg: dict[str, float]) -> tuple[dict[str, np.ndarray], str]:
    model = _model(robot)
    data = mujoco.MjData(model)
    for name, value in poppy_deg.items():
        data.qpos[model.joint(name).qposadr[0]] = math.radians(value)
    mujoco.mj_kinematics(model, data)
    root = model.body(1).name
    rot = data.xmat[1].reshape(3, 3)
    out = {model.body(i).name: rot.T @ (data.xpos[i] - data.xpos[1]) for i in range(1, model.nbody)}
    return out, root


@pytest.mark.parametrize("seed", range(3))
def test_ergo_jr_poppy_angles_drive_the_urdf_like_pypot(seed: int) -> None:
    """pypot's IK chain feeds the Ergo Jr URDF the motor angle: sign * (poppy angle + offset)."""
    rng = np.random.default_rng(seed)
    profile = load_profile("ergo-jr")
    poppy = {n: float(rng.uniform(*m.angle_limit)) for n, m in profile.motors.items()}
    urdf = {
        n: (1 if profile.motors[n].orientation == "direct" else -1) * (v + profile.motors[n].offset)
        for n, v in poppy.items()
    }
    expected = _urdf_positions("ergo-jr", urdf)
    got, _ = _mujoco_positions("ergo-jr", poppy)
    for link, position in expected.items():
        assert got[link] == pytest.approx(np.array(position), abs=1e-6), link


def _hands(poppy: dict[str, float]) -> dict[str, np.ndarray]:
    model = _model("torso")
    data = mujoco.MjData(model)
    for name, value in poppy.items():
        data.qpos[model.joint(name).qposadr[0]] = math.radians(value)
    mujoco.mj_kinematics(model, data)
    hands = {}
    for side in "lr":
        body = model.body(f"{side}_forearm").id
        hands[side] = data.xpos[body] + data.xmat[body].reshape(3, 3) @ [0.0, 0.1, 0.0]
        hands[side + "_shoulder"] = data.xpos[model.body(f"{side}_shoulder").id].copy()
    return hands


def test_torso_zero_pose_has_the_arms_down() -> None:
    hands = _hands({})
    for side in "lr":
        assert hands[side][2] < hands[side + "_shoulder"][2] - 0.2


@pytest.mark.parametrize(
    ("joint", "angle", "side", "axis", "direction"),
    [
        ("l_shoulder_x", 30.0, "l", 0, +1),  # abduction: left hand goes left (+x)
        ("r_shoulder_x", -30.0, "r", 0, -1),  # mirrored: right hand goes right (-x)
        ("l_shoulder_y", 30.0, "l", 1, -1),  # forward raise (front is -y), up to 155°
        ("r_shoulder_y", -30.0, "r", 1, -1),  # mirrored
        ("l_elbow_y", -30.0, "l", 1, -1),  # flexion brings the hand forward
        ("r_elbow_y", 30.0, "r", 1, -1),
    ],
)
def test_torso_arm_directions(
    joint: str, angle: float, side: str, axis: int, direction: int
) -> None:
    before = _hands({})[side][axis]
    after = _hands({joint: angle})[side][axis]
    assert (after - before) * direction > 0.02
