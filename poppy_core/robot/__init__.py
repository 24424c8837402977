"""Robot layer: configs and profiles (pypot JSON compatible), ``Motor``, ``Robot`` and their loops.

A robot is built whole (with its creature) by the package's faces, ``poppy_core.from_profile``,
``from_config`` and ``autodetect``; ``robot.factory`` builds the plain robot they start from.
"""

from poppy_core.robot.calibration import (
    Calibration,
    JointCalibration,
    ReferencePosture,
    reference_posture,
)
from poppy_core.robot.calibration_session import (
    CalibrationAnswers,
    CalibrationEvent,
    CalibrationSession,
    JointDrift,
    JointReading,
    RangeWatch,
    check_calibration,
)
from poppy_core.robot.config import (
    DEFAULT_BAUDRATE,
    ControllerConfig,
    MotorConfig,
    ProfileHeader,
    RobotConfig,
)
from poppy_core.robot.config_io import config_to_text, dump_config, load_config
from poppy_core.robot.factory import start_emulators, with_ports
from poppy_core.robot.goto import GotoHandle, GotoRunner
from poppy_core.robot.group import MotorGroup
from poppy_core.robot.health import BusHealth
from poppy_core.robot.motor import Motor
from poppy_core.robot.profile_store import SavedProfile, save_user_profile
from poppy_core.robot.profiles import (
    PROFILE_FILE,
    ProfileInfo,
    find_profile,
    list_profiles,
    load_profile,
    profile_dirs,
    user_profile_dir,
)
from poppy_core.robot.pypot_factories import from_remote
from poppy_core.robot.robot import Robot
from poppy_core.robot.startup import ReturnDelayIssue
from poppy_core.robot.sync import (
    BASE_LOOPS,
    LIGHT_LOOPS,
    BusSync,
    LoopSpec,
    LoopStats,
    SyncStats,
    loops_for,
)

__all__ = [
    "BASE_LOOPS",
    "DEFAULT_BAUDRATE",
    "LIGHT_LOOPS",
    "PROFILE_FILE",
    "BusHealth",
    "BusSync",
    "Calibration",
    "CalibrationAnswers",
    "CalibrationEvent",
    "CalibrationSession",
    "ControllerConfig",
    "GotoHandle",
    "GotoRunner",
    "JointCalibration",
    "JointDrift",
    "JointReading",
    "LoopSpec",
    "LoopStats",
    "Motor",
    "MotorConfig",
    "MotorGroup",
    "ProfileHeader",
    "ProfileInfo",
    "RangeWatch",
    "ReferencePosture",
    "ReturnDelayIssue",
    "Robot",
    "RobotConfig",
    "SavedProfile",
    "SyncStats",
    "check_calibration",
    "config_to_text",
    "dump_config",
    "find_profile",
    "from_remote",
    "list_profiles",
    "load_config",
    "load_profile",
    "loops_for",
    "profile_dirs",
    "reference_posture",
    "save_user_profile",
    "start_emulators",
    "user_profile_dir",
    "with_ports",
]
