"""A robot's arms seen through its chains' forward kinematics, for the mimic tests."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from poppy_core.robot import Robot


def arm_directions(chain: Any, angles: Mapping[str, float]) -> tuple[np.ndarray, np.ndarray]:
    """A chain's upper arm and forearm (unit vectors, base frame) by forward kinematics."""
    arm = [m.name for m in chain.active_motors]
    frames = chain.model.frames(dict(angles))
    shoulder, elbow, hand = (frames[n][:3, 3] for n in (arm[1], arm[-1], "tip"))
    upper, fore = elbow - shoulder, hand - elbow
    return upper / np.linalg.norm(upper), fore / np.linalg.norm(fore)


def robot_frame(chain: Any) -> np.ndarray:
    """Rows forward, left, up in the chain's base frame: at the zero posture the upper arm hangs
    down and the forearm points forward (the profiles' calibration posture)."""
    present = {m.name: m.present_position for m in chain.motors}
    arm = [m.name for m in chain.active_motors]
    hanging, ahead = arm_directions(chain, {**present, **dict.fromkeys(arm, 0.0)})
    up = -hanging
    forward = ahead - up * (ahead @ up)
    forward /= np.linalg.norm(forward)
    return np.array([forward, np.cross(up, forward), up])


def robot_arms(robot: Robot) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Each robot arm's (upper arm, forearm) in the robot's (forward, left, up)."""
    out = {}
    for side, chain in (("left", robot.l_arm_chain), ("right", robot.r_arm_chain)):
        frame = robot_frame(chain)
        upper, fore = arm_directions(chain, {m.name: m.present_position for m in chain.motors})
        out[side] = (frame @ upper, frame @ fore)
    return out


def angle_deg(a: Any, b: Any) -> float:
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    cos = float(a @ b / (np.linalg.norm(a) * np.linalg.norm(b)))
    return math.degrees(math.acos(max(-1.0, min(1.0, cos))))
