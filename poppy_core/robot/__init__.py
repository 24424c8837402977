"""Robot layer: configs and profiles (pypot JSON compatible); more is added by the robot modules."""

from poppy_core.robot.config import (
    DEFAULT_BAUDRATE,
    ControllerConfig,
    MotorConfig,
    ProfileHeader,
    RobotConfig,
)
from poppy_core.robot.config_io import config_to_text, dump_config, load_config
from poppy_core.robot.profiles import (
    PROFILE_FILE,
    ProfileInfo,
    find_profile,
    list_profiles,
    load_profile,
    profile_dirs,
    user_profile_dir,
)

__all__ = [
    "DEFAULT_BAUDRATE",
    "PROFILE_FILE",
    "ControllerConfig",
    "MotorConfig",
    "ProfileHeader",
    "ProfileInfo",
    "RobotConfig",
    "config_to_text",
    "dump_config",
    "find_profile",
    "list_profiles",
    "load_config",
    "load_profile",
    "profile_dirs",
    "user_profile_dir",
]
