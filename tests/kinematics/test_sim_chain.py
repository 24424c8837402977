"""Chains on the MuJoCo creatures: the models and the chains agree on every pose, with physics a
goto ends near its target (Ergo Jr, Torso, Humanoid arms); head_follow follows."""

from __future__ import annotations

import math
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from poppy_core import from_profile
from poppy_core.creatures.head_follow import HeadFollow
from poppy_core.kinematics.transforms import quat_matrix
from poppy_core.motion.cartesian import RobotChain
from poppy_core.motion.chains import chains_from_config
from poppy_core.robot import Robot, load_profile
from poppy_core.robot.frames import to_motor
from tests.helpers.fixtures import ergo_fixture
from tests.helpers.waiting import eventually

mujoco = pytest.importorskip("mujoco")

PROFILES = Path(__file__).resolve().parents[2] / "profiles"

TIP_M = np.array([0.0, 0.0, -0.07])


ergo = ergo_fixture(scope="module", sim="mujoco", stiff=True)


def _simulated_tip(robot: Robot) -> np.ndarray:
    """Where the physics put the tip point, in the chain's base frame."""
    sim = robot.simulation
    body = np.array(sim.get_object_position("tip", relative_to="base_link"))
    turn = quat_matrix(sim.get_object_orientation("tip", relative_to="base_link"))
    return body + turn @ TIP_M


def _wait_until(condition, timeout_s: float) -> bool:  # type: ignore[no-untyped-def]
    return eventually(lambda: bool(condition()), timeout_s=timeout_s, interval_s=0.05)


@pytest.mark.parametrize("target", [(0.1, -0.1, 0.12), (0.0, -0.15, 0.08), (-0.12, 0.0, 0.15)])
def test_goto_ends_within_5_mm_with_physics(
    ergo: Robot, target: tuple[float, float, float]
) -> None:
    ergo.chain.goto(target, duration=1.0, wait=True)
    assert _wait_until(lambda: np.linalg.norm(_simulated_tip(ergo) - target) < 0.005, 8.0), (
        f"tip at {_simulated_tip(ergo)}, target {target}"
    )
    # the chain's own reading (the motors' present positions, 0.29° steps read at 50 Hz)
    # agrees with the physics
    assert _wait_until(
        lambda: np.linalg.norm(ergo.chain.position - _simulated_tip(ergo)) < 0.01, 8.0
    ), f"chain at {ergo.chain.position}, tip at {_simulated_tip(ergo)}"


def test_head_follow_is_attached_only_with_mujoco() -> None:
    with from_profile("ergo-jr", sim=True) as ideal:
        assert "head_follow" not in ideal.primitive_names


def test_head_follow_follows_an_object(ergo: Robot) -> None:
    follow = ergo.head_follow
    assert isinstance(follow, HeadFollow)
    ergo.simulation.add_object("sphere", "ball", (0.12, -0.06, 0.1), size=0.01, mass=0.01)
    assert follow.followed() == "ball"
    follow.start()
    try:

        def near() -> bool:
            ball = np.array(ergo.simulation.get_object_position("ball", relative_to="base_link"))
            return bool(np.linalg.norm(_simulated_tip(ergo) - (ball + follow.offset)) < 0.01)

        assert _wait_until(near, 8.0)
        assert follow.error is None
    finally:
        follow.stop()


# ---------------------------------------------------------------------- every creature


@pytest.mark.parametrize("kind", ["ergo-jr", "torso", "humanoid"])
def test_chains_and_models_agree_on_random_poses(kind: str) -> None:
    """The same user angles put a chain's tip and the MuJoCo model's at the same point."""
    config = load_profile(kind)
    chains = chains_from_config(config)
    model = mujoco.MjModel.from_xml_path(str(PROFILES / kind / "model.xml"))
    data = mujoco.MjData(model)
    rng = np.random.default_rng(13)
    for _ in range(40):
        user = {n: float(rng.uniform(*m.user_angle_limit)) for n, m in config.motors.items()}
        for name, angle in user.items():
            entry = config.motors[name]
            motor_deg = to_motor(angle, entry.orientation, entry.offset)
            data.qpos[model.joint(name).qposadr[0]] = math.radians(motor_deg)
        mujoco.mj_kinematics(model, data)
        for chain in chains.values():
            last = model.joint(chain.names[-1])
            body, base = data.body(int(last.bodyid[0])), data.body(chain.base)
            tip = body.xpos + body.xmat.reshape(3, 3) @ chain.tip
            in_base = base.xmat.reshape(3, 3).T @ (tip - base.xpos)
            expected = chain.forward({n: user[n] for n in chain.names})[:3, 3]
            assert np.linalg.norm(in_base - expected) < 1e-5, (kind, chain.name, user)


def _chain_tip_in_sim(robot: Robot, chain: RobotChain) -> np.ndarray:
    """Where the physics put the chain's tip point, in the chain's base frame."""
    sim = robot.simulation
    model = chain.model
    last = model.names[-1]
    link = str(sim.model.body(int(sim.model.joint(last).bodyid[0])).name)
    body = np.array(sim.get_object_position(link, relative_to=model.base))
    turn = quat_matrix(sim.get_object_orientation(link, relative_to=model.base))
    return body + turn @ model.tip


@pytest.fixture(scope="module")
def torso() -> Iterator[Robot]:
    with from_profile("torso", sim="mujoco") as robot:
        robot.compliant = False
        yield robot


# Reachable targets: the tips of arm postures (user frame), so the test does not depend on
# guessing the workspace; the solver starts from wherever the arm is. What is left is the
# servos' sag under the arm's weight (docs/kinematics.md: 1-2 mm on the Torso, 3-4 mm on the
# Humanoid, whose trunk gives way too; 8 mm with its arm raised 60° forward from rest).
ARM_POSTURES = [
    {"shoulder_y": -20.0, "shoulder_x": 15.0, "arm_z": 0.0, "elbow_y": -40.0},
    {"shoulder_y": -45.0, "shoulder_x": 10.0, "arm_z": 15.0, "elbow_y": -30.0},
]


def _target(robot: Robot, chain: RobotChain, side: str, posture: dict[str, float]) -> np.ndarray:
    mirror = {"shoulder_y": 1.0, "shoulder_x": -1.0, "arm_z": -1.0, "elbow_y": 1.0}
    angles = {f"{side}_{j}": (1.0 if side == "l" else mirror[j]) * v for j, v in posture.items()}
    return np.asarray(chain.forward(angles)[:3, 3])


def _goto_ends_near(robot: Robot, chain: RobotChain, target: np.ndarray) -> None:
    chain.goto(target, duration=1.0, wait=True)

    def near() -> bool:
        return bool(np.linalg.norm(_chain_tip_in_sim(robot, chain) - target) < 0.005)

    assert _wait_until(near, 8.0), f"tip at {_chain_tip_in_sim(robot, chain)}, target {target}"

    def agrees() -> bool:  # the present positions a sync period late on a busy machine
        return bool(np.linalg.norm(chain.position - _chain_tip_in_sim(robot, chain)) < 0.01)

    assert _wait_until(agrees, 8.0), (
        f"chain at {chain.position}, tip {_chain_tip_in_sim(robot, chain)}"
    )


@pytest.mark.parametrize("side", ["l", "r"])
@pytest.mark.parametrize("posture", range(len(ARM_POSTURES)))
def test_torso_arm_goto_ends_within_5_mm_with_physics(
    torso: Robot, side: str, posture: int
) -> None:
    chain = torso.extensions[f"{side}_arm_chain"]
    assert isinstance(chain, RobotChain)
    _goto_ends_near(torso, chain, _target(torso, chain, side, ARM_POSTURES[posture]))


def test_humanoid_arm_goto_ends_within_5_mm_with_physics() -> None:
    with from_profile("humanoid", sim="mujoco") as robot:
        robot.compliant = False
        robot.simulation.reset()  # it fell while its servos were off
        robot.goto_position({m.name: 0.0 for m in robot.motors}, 0.5, wait=True)
        for posture in ARM_POSTURES:
            for side in "lr":
                chain = robot.extensions[f"{side}_arm_chain"]
                assert isinstance(chain, RobotChain)
                _goto_ends_near(robot, chain, _target(robot, chain, side, posture))
