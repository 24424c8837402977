"""Chains on a MuJoCo Ergo Jr: with physics a goto ends near its target; head_follow follows."""

from __future__ import annotations

import time
from collections.abc import Iterator

import numpy as np
import pytest

from poppy_core.creatures import from_profile
from poppy_core.creatures.head_follow import HeadFollow
from poppy_core.kinematics.transforms import quat_matrix
from poppy_core.robot import Robot

pytest.importorskip("mujoco")

TIP_M = np.array([0.0, 0.0, -0.07])


@pytest.fixture(scope="module")
def ergo() -> Iterator[Robot]:
    with from_profile("ergo-jr", sim="mujoco") as robot:
        robot.compliant = False
        yield robot


def _simulated_tip(robot: Robot) -> np.ndarray:
    """Where the physics put the tip point, in the chain's base frame."""
    sim = robot.simulation
    body = np.array(sim.get_object_position("tip", relative_to="base_link"))
    turn = quat_matrix(sim.get_object_orientation("tip", relative_to="base_link"))
    return body + turn @ TIP_M


def _wait_until(condition, timeout_s: float) -> bool:  # type: ignore[no-untyped-def]
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if condition():
            return True
        time.sleep(0.05)
    return condition()


@pytest.mark.parametrize("target", [(0.1, -0.1, 0.12), (0.0, -0.15, 0.08), (-0.12, 0.0, 0.15)])
def test_goto_ends_within_5_mm_with_physics(
    ergo: Robot, target: tuple[float, float, float]
) -> None:
    ergo.chain.goto(target, duration=1.0, wait=True)
    assert _wait_until(lambda: np.linalg.norm(_simulated_tip(ergo) - target) < 0.005, 3.0), (
        f"tip at {_simulated_tip(ergo)}, target {target}"
    )
    # the chain's own reading (the motors' present positions, 0.29° steps read at 50 Hz)
    # agrees with the physics
    assert np.linalg.norm(ergo.chain.position - _simulated_tip(ergo)) < 0.01


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
