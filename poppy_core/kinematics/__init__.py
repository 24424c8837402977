"""Kinematics: chains read from a URDF or MJCF, forward kinematics and inverse kinematics.

A leaf room: numpy (and mujoco, only to read MJCF files); nothing of poppy but its errors. The
robot-bound chains (``robot.chain``, ``robot.l_arm_chain``) live in ``poppy_core.motion.cartesian``.
"""

from poppy_core.kinematics.chain import Chain, ChainJoint, make_target, rotation_degrees
from poppy_core.kinematics.description import (
    JointDescription,
    KinematicDescription,
    load_description,
    parse_mjcf,
    parse_urdf,
)
from poppy_core.kinematics.kernel import Kinematics
from poppy_core.kinematics.solver import Solution, SolverOptions, Target
from poppy_core.kinematics.spec import (
    ChainSpec,
    KinematicsSpec,
    MotorFrame,
    build_chains,
    find_model,
)
from poppy_core.kinematics.transforms import matrix_rpy, rpy_matrix

__all__ = [
    "Chain",
    "ChainJoint",
    "ChainSpec",
    "JointDescription",
    "KinematicDescription",
    "Kinematics",
    "KinematicsSpec",
    "MotorFrame",
    "Solution",
    "SolverOptions",
    "Target",
    "build_chains",
    "find_model",
    "load_description",
    "make_target",
    "matrix_rpy",
    "parse_mjcf",
    "parse_urdf",
    "rotation_degrees",
    "rpy_matrix",
]
