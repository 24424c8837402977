"""Forward kinematics: hand-derived Ergo Jr poses, pypot's recorded answers, URDF against MJCF."""

from __future__ import annotations

import json
import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from poppy_core.kinematics import (
    Chain,
    MotorFrame,
    build_chains,
    load_description,
)
from poppy_core.motion.chains import group_expander, kinematics_spec
from poppy_core.robot import load_profile

DATA = Path(__file__).parent / "data"
PROFILES = Path(__file__).resolve().parents[2] / "profiles"

# Ergo Jr, profiles/ergo-jr/poppy_ergo_jr.urdf, zero pose (pypot feeds the URDF the motor angle,
# all 0 here). Walking the joint origins: m1 +z 0.0328, m2 +z 0.0240 then the frame turns 90°
# about x (its y is now up), m3 +0.054 along that y (up), m4 +0.0298 (up) then a half turn about
# x, m5 (0, -0.0152, -0.048): up 0.0152 and back 0.048, m6 0.054 further back, and the tip
# 0.07 back again: x = 0, y = -(0.048 + 0.054 + 0.07),
# z = 0.0328 + 0.0240 + 0.054 + 0.0298 + 0.0152.
M1_Z, M2_Z, M3_Y, M4_Y = 0.0327993216120967, 0.0240006783879033, 0.054, 0.0298217741221248
M5_Y, M5_Z, M6_Y, TIP = -0.0151782258778753, -0.048, 0.054, 0.07
ZERO_TIP = np.array([0.0, M5_Z - M6_Y - TIP, M1_Z + M2_Z + M3_Y + M4_Y - M5_Y])


def test_zero_pose_by_hand(ergo_chain: Chain) -> None:
    pose = ergo_chain.forward()
    assert pose[:3, 3] == pytest.approx(ZERO_TIP, abs=1e-9)
    assert pose[:3, 0] == pytest.approx([0.0, 0.0, 1.0], abs=1e-9)  # the tip's x axis is up


def test_base_turn_by_hand(ergo_chain: Chain) -> None:
    # m1 (direct, URDF axis -z) at +90° turns the whole arm by -90° about z: (x, y) -> (y, -x)
    tip = ergo_chain.forward({"m1": 90.0})[:3, 3]
    assert tip == pytest.approx([ZERO_TIP[1], -ZERO_TIP[0], ZERO_TIP[2]], abs=1e-9)


def test_shoulder_turn_by_hand(ergo_chain: Chain) -> None:
    # m2 is indirect: +90° is -90° of the URDF joint, whose axis is -x: +90° about x, around
    # the point (0, 0, M1_Z + M2_Z); (y, z) relative to it becomes (-z, y)
    pivot = np.array([0.0, 0.0, M1_Z + M2_Z])
    relative = ZERO_TIP - pivot
    expected = pivot + np.array([0.0, -relative[2], relative[1]])
    assert ergo_chain.forward({"m2": 90.0})[:3, 3] == pytest.approx(expected, abs=1e-9)


def test_sequence_and_mapping_agree(ergo_chain: Chain) -> None:
    angles = [10.0, -20.0, 30.0, -40.0, 50.0, -60.0]
    by_name = dict(zip(ergo_chain.names, angles, strict=True))
    assert np.allclose(ergo_chain.forward(angles), ergo_chain.forward(by_name))


def _fixture() -> dict[str, dict[str, dict[str, list[list[float]]]]]:
    data: dict[str, dict[str, dict[str, list[list[float]]]]] = json.loads(
        (DATA / "pypot_chains.json").read_text(encoding="utf-8")
    )["creatures"]
    return data


@pytest.mark.parametrize(
    ("kind", "name"),
    [(k, n) for k, chains in _fixture().items() for n in chains],
)
def test_same_tip_as_pypot(
    kind: str, name: str, creature_chains: dict[str, dict[str, Chain]]
) -> None:
    """pypot's IKChain (recorded by bench/ik_fixture.py) and ours agree within 1 mm."""
    recorded = _fixture()[kind][name]
    chain = creature_chains[kind][name]
    assert list(chain.names) == recorded["motors"]
    for angles, expected in zip(recorded["poses"], recorded["tip_poses"], strict=True):
        pose = chain.forward(angles)
        assert np.linalg.norm(pose[:3, 3] - np.array(expected)[:3, 3]) < 1e-3
        assert np.allclose(pose[:3, :3], np.array(expected)[:3, :3], atol=1e-6)


@pytest.mark.parametrize("kind", ["ergo-jr", "torso", "humanoid"])
def test_mjcf_chains_match_urdf_chains(kind: str) -> None:
    """A creature's MuJoCo model and its URDF give the same tips for the same angles.

    Both take the motor's own angle; the URDF's reversed motors are turned in the model itself,
    and the model's bodies are drawn at the home pose (joint ``ref``).
    """
    pytest.importorskip("mujoco")
    config = load_profile(kind)
    assert config.kinematics is not None
    spec = kinematics_spec(config.kinematics)
    urdf = load_description(PROFILES / kind / spec.model)
    mjcf = load_description(PROFILES / kind / "model.xml")
    assert (urdf.joint_frame, mjcf.joint_frame) == ("motor", "motor")
    frames = {
        n: MotorFrame(1.0 if m.orientation == "direct" else -1.0, m.offset, m.user_angle_limit)
        for n, m in config.motors.items()
    }
    from_urdf = build_chains(spec, urdf, frames, group_expander(config))
    plain = replace(spec, reversed=(), chains=tuple(replace(c, reversed=()) for c in spec.chains))
    from_mjcf = build_chains(plain, mjcf, frames, group_expander(config))
    rng = np.random.default_rng(5)
    for name, chain in from_urdf.items():
        for _ in range(20):
            angles = {n: rng.uniform(*config.motors[n].user_angle_limit) for n in chain.names}
            assert np.allclose(chain.forward(angles), from_mjcf[name].forward(angles), atol=1e-5)


def test_frames_end_at_the_tip(ergo_chain: Chain) -> None:
    frames = ergo_chain.frames({"m3": 20.0})
    assert list(frames) == [*ergo_chain.names, "tip"]
    assert np.allclose(frames["tip"], ergo_chain.forward({"m3": 20.0}))
    assert math.isclose(float(np.linalg.norm(frames["m1"][:3, 3])), M1_Z, abs_tol=1e-9)
