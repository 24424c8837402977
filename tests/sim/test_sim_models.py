"""The MJCF models: generated from the URDFs, load cleanly, named and signed like the profiles."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
from sim_helpers import PROFILES, ROBOTS

from poppy_core.creatures.postures import humanoid_sit
from poppy_core.kinematics.transforms import quat_mul
from poppy_core.robot.frames import to_motor
from poppy_core.robot.profiles import load_profile
from poppy_core.sim.home_pose import reversed_joints
from poppy_core.sim.mjcf import ROBOTS as URDF_FILES
from poppy_core.sim.mjcf import generate
from poppy_core.sim.urdf import (
    Quat,
    Vec3,
    parse_urdf,
    quat_from_axis_angle,
    quat_from_rpy,
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


# ---------------------------------------------------------------------- joint frames
# A model's joint angle is the motor's own angle; the URDF takes that angle too, turned the other
# way for the profile's ``kinematics.reversed`` motors (docs/simulation.md, "Angles").


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


def _posed(robot: str, user_deg: dict[str, float]) -> tuple[Any, Any]:
    """The model and its data with every motor at ``user_deg`` (poppy's frame, 0 if absent)."""
    model = _model(robot)
    data = mujoco.MjData(model)
    for name, entry in load_profile(robot).motors.items():
        motor_deg = to_motor(user_deg.get(name, 0.0), entry.orientation, entry.offset)
        data.qpos[model.joint(name).qposadr[0]] = math.radians(motor_deg)
    mujoco.mj_kinematics(model, data)
    return model, data


@pytest.mark.parametrize("robot", ROBOTS)
@pytest.mark.parametrize("seed", range(3))
def test_the_model_is_the_urdf_driven_by_the_motor_angles(robot: str, seed: int) -> None:
    """pypot feeds the URDF the motor angle, sign * (angle + offset); so does the model."""
    rng = np.random.default_rng(seed)
    profile = load_profile(robot)
    reversed_ = reversed_joints(PROFILES, robot)
    user = {n: float(rng.uniform(*m.user_angle_limit)) for n, m in profile.motors.items()}
    motor = {
        n: to_motor(v, profile.motors[n].orientation, profile.motors[n].offset)
        for n, v in user.items()
    }
    expected = _urdf_positions(robot, {n: -v if n in reversed_ else v for n, v in motor.items()})
    _, data = _posed(robot, user)
    rot = data.xmat[1].reshape(3, 3)
    for link, position in expected.items():
        got = rot.T @ (data.body(link).xpos - data.xpos[1])
        assert got == pytest.approx(np.array(position), abs=1e-5), link


def test_reversed_motors_are_the_profiles() -> None:
    assert reversed_joints(PROFILES, "ergo-jr") == frozenset()
    assert reversed_joints(PROFILES, "torso") == {"r_shoulder_x"}
    assert reversed_joints(PROFILES, "humanoid") == {"r_shoulder_x", "l_knee_y"}


TIP = np.array([0.0, 0.18, 0.0])  # the arm chains' tip, in the forearm's frame (pypot's)


def _hands(robot: str, user_deg: dict[str, float]) -> dict[str, np.ndarray]:
    model, data = _posed(robot, user_deg)
    out = {}
    for side in "lr":
        body = model.body(f"{side}_forearm").id
        out[side] = data.xpos[body] + data.xmat[body].reshape(3, 3) @ TIP
        out[side + "_shoulder"] = data.body(f"{side}_shoulder").xpos.copy()
        out[side + "_elbow"] = data.xpos[body].copy()
    return out


@pytest.mark.parametrize("robot", ["torso", "humanoid"])
def test_home_pose_has_the_arms_down(robot: str) -> None:
    """At 0° the upper arms hang; the Torso's forearms point forward (elbows at 90°, offset -90:
    the Poppy Torso photographs and pypot's V-REP scene), the Humanoid's hang straight."""
    hands = _hands(robot, {})
    for side in "lr":
        shoulder, elbow, hand = hands[side + "_shoulder"], hands[side + "_elbow"], hands[side]
        assert elbow[2] < shoulder[2] - 0.1
        assert abs(elbow[1] - shoulder[1]) < 0.03
        if robot == "torso":
            assert hand[1] < elbow[1] - 0.15  # forward is -y
            assert hand[2] == pytest.approx(elbow[2], abs=0.02)
        else:
            assert hand[2] < elbow[2] - 0.15


@pytest.mark.parametrize("robot", ["torso", "humanoid"])
def test_home_pose_has_the_head_level(robot: str) -> None:
    """head_y's offset (20°) cancels the URDF's 20° head tilt only when read in the motor frame."""
    _, data = _posed(robot, {})
    relative = data.body("chest").xmat.reshape(3, 3).T @ data.body("head").xmat.reshape(3, 3)
    assert relative == pytest.approx(np.eye(3), abs=0.01)


@pytest.mark.parametrize("robot", ["torso", "humanoid"])
@pytest.mark.parametrize(
    ("joint", "angle", "axis", "direction"),
    [
        ("l_shoulder_x", 30.0, 0, +1),  # abduction: the left hand goes left (+x)
        ("r_shoulder_x", -30.0, 0, -1),  # mirrored: the right hand goes right (-x)
        ("l_shoulder_y", -30.0, 1, -1),  # forward raise (front is -y), down to -210°
        ("r_shoulder_y", -30.0, 1, -1),  # the same sign on both sides
        ("l_elbow_y", -30.0, 2, +1),  # more flexion lifts the hand (forearm forward first)
        ("r_elbow_y", -30.0, 2, +1),
        ("l_arm_z", -30.0, 0, -1),  # with the elbow bent, the forearm turns inward
        ("r_arm_z", 30.0, 0, +1),
    ],
)
def test_arm_directions(robot: str, joint: str, angle: float, axis: int, direction: int) -> None:
    bent = {"l_elbow_y": -90.0, "r_elbow_y": -90.0} if robot == "humanoid" else {}
    side = joint[0]
    before = _hands(robot, bent)[side][axis]
    after = _hands(robot, {**bent, joint: bent.get(joint, 0.0) + angle})[side][axis]
    assert (after - before) * direction > 0.02


@pytest.mark.parametrize(("joint", "angle"), [("bust_y", 20.0), ("abs_y", 20.0)])
def test_positive_trunk_pitch_bends_forward(joint: str, angle: float) -> None:
    """bust_y [-27, 67] and abs_y [-12, 50] in the user frame: the long way is forward."""
    _, data = _posed("humanoid", {})
    before = data.body("head").xpos.copy()
    _, data = _posed("humanoid", {joint: angle})
    assert data.body("head").xpos[1] < before[1] - 0.02


def test_pypot_sit_bends_both_knees_forward() -> None:
    """pypot's SitPosition (hip_y -39, knee_y 134 on both legs): thighs forward, shins folded
    back under them, the knee in front of the hip and the ankle."""
    _, data = _posed("humanoid", humanoid_sit())
    for side in "lr":
        hip = data.body(f"{side}_thigh").xpos
        knee = data.body(f"{side}_shin").xpos
        ankle = data.body(f"{side}_foot").xpos
        assert knee[1] < hip[1] - 0.05 and knee[1] < ankle[1] - 0.05, side
        assert np.linalg.norm(ankle - knee) == pytest.approx(0.18, abs=0.01)
