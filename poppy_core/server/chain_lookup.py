"""The robot's kinematic chains as the server sees them: lookup by name and their tip, as data."""

from __future__ import annotations

import math
from typing import Any

from poppy_core.motion.cartesian import RobotChain
from poppy_core.motion.chains import robot_chains
from poppy_core.robot import Robot
from poppy_core.server.errors import ApiError

CHAIN_TIP = (
    "the chains are listed by /api/v1/chains "
    "(Ergo Jr: chain; Torso and Humanoid: l_arm_chain, r_arm_chain)"
)


def find_chain(robot: Robot, name: str) -> RobotChain:
    """The chain ``name``, or ``ApiError("not_found")`` naming the robot's chains."""
    chains = robot_chains(robot)
    chain = chains.get(name)
    if chain is None:
        known = ", ".join(chains) or "none"
        message = f"Chain '{name}' does not exist for this robot (chains: {known})"
        raise ApiError("not_found", message, tip=CHAIN_TIP)
    return chain


def chain_state(chain: RobotChain) -> dict[str, Any]:
    """A chain's motors and tip: position (m), x axis, roll/pitch/yaw (degrees), 4x4 pose."""
    pose = chain.pose
    return {
        "name": chain.name,
        "label": chain.label,
        "motors": [m.name for m in chain.motors],
        "active_motors": [m.name for m in chain.active_motors],
        "base": chain.base,
        "position": [float(v) for v in pose[:3, 3]],
        "orientation": [float(v) for v in pose[:3, 0]],
        "rpy_deg": [math.degrees(v) for v in chain.rpy],
        "pose": pose.tolist(),
    }
