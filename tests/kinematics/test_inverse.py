"""Inverse kinematics: round trips within the limits, orientations, passive joints, out of reach."""

from __future__ import annotations

import numpy as np
import pytest

from poppy_core.errors import KinematicsError, PoppyError
from poppy_core.kinematics import Chain, SolverOptions, rpy_matrix


def _random_pose(chain: Chain, rng: np.random.Generator) -> dict[str, float]:
    return {j.name: float(rng.uniform(*j.limits_deg)) for j in chain.joints}


def _within_limits(chain: Chain, angles: dict[str, float]) -> bool:
    limits = {j.name: j.limits_deg for j in chain.joints}
    return all(limits[n][0] <= a <= limits[n][1] for n, a in angles.items())


@pytest.mark.parametrize(
    ("kind", "name"),
    [
        ("ergo-jr", "chain"),
        ("torso", "l_arm_chain"),
        ("torso", "r_arm_chain"),
        ("humanoid", "l_arm_chain"),
    ],
)
def test_round_trip_within_limits(
    kind: str, name: str, creature_chains: dict[str, dict[str, Chain]]
) -> None:
    chain = creature_chains[kind][name]
    rng = np.random.default_rng(11)
    for _ in range(40):
        pose = _random_pose(chain, rng)
        target = chain.forward(pose)[:3, 3]
        passive = {n: pose[n] for n in chain.names if n not in chain.active_names}
        angles = chain.solve(target, seed={**chain.rest_deg, **passive})
        assert set(angles) == set(chain.active_names)
        assert _within_limits(chain, angles)
        reached = chain.forward({**pose, **angles})[:3, 3]
        assert np.linalg.norm(reached - target) < 1e-3


def test_passive_joints_stay_at_their_seed(creature_chains: dict[str, dict[str, Chain]]) -> None:
    chain = creature_chains["torso"]["l_arm_chain"]
    torso = {"abs_z": 25.0, "bust_y": -10.0, "bust_x": 5.0}
    target = chain.forward({**torso, "l_shoulder_y": 40.0, "l_elbow_y": -40.0})[:3, 3]
    angles = chain.solve(target, seed=torso)
    assert set(angles).isdisjoint(torso)
    assert np.linalg.norm(chain.forward({**torso, **angles})[:3, 3] - target) < 1e-3


def test_seed_near_the_answer_keeps_the_answer_near(ergo_chain: Chain) -> None:
    pose = {"m1": 20.0, "m2": -30.0, "m3": 40.0, "m4": 10.0, "m5": 30.0, "m6": -20.0}
    target = ergo_chain.forward(pose)[:3, 3]
    angles = ergo_chain.solve(target, seed=pose)
    assert max(abs(angles[n] - pose[n]) for n in pose) < 0.5


def test_x_axis_orientation_round_trip(ergo_chain: Chain) -> None:
    rng = np.random.default_rng(2)
    for _ in range(20):
        pose = ergo_chain.forward(_random_pose(ergo_chain, rng))
        angles = ergo_chain.solve(pose[:3, 3], pose[:3, 0])
        reached = ergo_chain.forward(angles)
        assert np.linalg.norm(reached[:3, 3] - pose[:3, 3]) < 1e-3
        assert np.degrees(np.arccos(np.clip(reached[:3, 0] @ pose[:3, 0], -1, 1))) < 1.0


def test_full_orientation_round_trip(ergo_chain: Chain) -> None:
    rng = np.random.default_rng(3)
    for _ in range(20):
        pose = ergo_chain.forward(_random_pose(ergo_chain, rng))
        angles = ergo_chain.solve(pose[:3, 3], pose[:3, :3])
        reached = ergo_chain.forward(angles)
        assert np.linalg.norm(reached[:3, 3] - pose[:3, 3]) < 1e-3
        assert np.allclose(reached[:3, :3], pose[:3, :3], atol=0.02)


def test_limits_hold_when_the_target_needs_a_joint_at_its_limit(ergo_chain: Chain) -> None:
    pose = {**ergo_chain.rest_deg, "m2": 125.0, "m3": -90.0}
    target = ergo_chain.forward(pose)[:3, 3]
    angles = ergo_chain.solve(target)
    assert _within_limits(ergo_chain, angles)
    assert np.linalg.norm(ergo_chain.forward(angles)[:3, 3] - target) < 1e-3


def test_out_of_reach_names_the_nearest_point(ergo_chain: Chain) -> None:
    target = [0.0, 0.0, 0.6]  # straight up, twice the arm's length
    with pytest.raises(KinematicsError) as caught:
        ergo_chain.solve(target)
    error = caught.value
    assert isinstance(error, PoppyError)
    assert error.nearest is not None and error.distance_m is not None
    assert error.distance_m == pytest.approx(np.linalg.norm(np.subtract(target, error.nearest)))
    assert error.distance_m > 0.2
    assert "nearest point" in str(error) and "(0.000, 0.000, 0.600)" in str(error)
    assert "\n" not in str(error)


def test_ten_centimetres_beyond_the_workspace_always_raises(ergo_chain: Chain) -> None:
    rng = np.random.default_rng(4)
    anchor = ergo_chain.kinematics.fixed[0][:3, 3]  # a point of the first joint's axis
    for _ in range(30):
        direction = rng.normal(size=3)
        direction /= np.linalg.norm(direction)
        target = anchor + direction * (ergo_chain.workspace_radius_m() + 0.1)
        with pytest.raises(KinematicsError):
            ergo_chain.solve(target)


def test_unreachable_orientation_raises(ergo_chain: Chain) -> None:
    # a reachable point, with the tip pointing straight down into the table
    target = ergo_chain.forward({"m2": -30.0, "m3": 30.0})[:3, 3]
    down = rpy_matrix(0.0, np.pi / 2, 0.0)
    with pytest.raises(KinematicsError, match="orientation"):
        ergo_chain.solve(target, down, options=SolverOptions(restarts=3))


@pytest.mark.parametrize(
    ("position", "orientation"),
    [
        ([0.1, 0.1], None),
        ([0.1, float("nan"), 0.1], None),
        ("abc", None),
        ([0.1, 0.1, 0.1], [0, 0, 0]),
        ([0.1, 0.1, 0.1], [[1, 0, 0], [0, 1, 0], [0, 0, -1]]),
        ([0.1, 0.1, 0.1], [1, 2]),
    ],
)
def test_malformed_targets_are_refused(
    ergo_chain: Chain, position: object, orientation: object
) -> None:
    with pytest.raises(KinematicsError):
        ergo_chain.solve(position, orientation)  # type: ignore[arg-type]


def test_unknown_joint_in_seed_or_forward(ergo_chain: Chain) -> None:
    with pytest.raises(KinematicsError, match="no joint 'm9'"):
        ergo_chain.forward({"m9": 3.0})
    with pytest.raises(KinematicsError, match="6 joints"):
        ergo_chain.forward([1.0, 2.0])


def test_closest_never_raises_for_reach(ergo_chain: Chain) -> None:
    angles, found = ergo_chain.closest([0.0, 0.0, 0.6])
    assert found.position_error_m > 0.2
    assert np.allclose(ergo_chain.forward(angles)[:3, 3], found.pose[:3, 3], atol=1e-9)


def test_same_target_same_answer(ergo_chain: Chain) -> None:
    target = ergo_chain.forward({"m1": 100.0, "m2": 80.0, "m3": -70.0})[:3, 3]
    assert ergo_chain.solve(target) == ergo_chain.solve(target)
