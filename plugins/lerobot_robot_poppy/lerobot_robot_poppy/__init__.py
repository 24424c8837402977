"""Poppy robots inside LeRobot: importing this registers the robot and teleoperator types.

LeRobot imports it by its distribution name (``register_third_party_plugins``) before it parses
``--robot.type``; its device factory finds ``PoppyErgoJr`` beside ``PoppyErgoJrConfig`` here.
"""

from lerobot_robot_poppy.config_poppy import (
    PoppyErgoJrConfig,
    PoppyErgoJrLeaderConfig,
    PoppyHumanoidConfig,
    PoppyHumanoidLeaderConfig,
    PoppyTorsoConfig,
    PoppyTorsoLeaderConfig,
)
from lerobot_robot_poppy.robot_poppy import PoppyErgoJr, PoppyHumanoid, PoppyRobot, PoppyTorso
from lerobot_robot_poppy.teleop_poppy import (
    PoppyErgoJrLeader,
    PoppyHumanoidLeader,
    PoppyLeader,
    PoppyTorsoLeader,
)

__all__ = [
    "PoppyErgoJr",
    "PoppyErgoJrConfig",
    "PoppyErgoJrLeader",
    "PoppyErgoJrLeaderConfig",
    "PoppyHumanoid",
    "PoppyHumanoidConfig",
    "PoppyHumanoidLeader",
    "PoppyHumanoidLeaderConfig",
    "PoppyLeader",
    "PoppyRobot",
    "PoppyTorso",
    "PoppyTorsoConfig",
    "PoppyTorsoLeader",
    "PoppyTorsoLeaderConfig",
]
