"""Robot layer: configs and profiles (pypot JSON compatible); more is added by the robot modules.

``from_config``, ``from_profile``, ``autodetect`` and ``from_json`` are the assembly's (a robot
with its creature, ``poppy_core.assembly``), re-exported here on first use by ``__getattr__``:
the one import that climbs, by design (docs/internals.md, "The composition root").
"""

from typing import TYPE_CHECKING, Any

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
    "autodetect",
    "check_calibration",
    "config_to_text",
    "dump_config",
    "find_profile",
    "from_config",
    "from_json",
    "from_profile",
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

if TYPE_CHECKING:
    from poppy_core.assembly import autodetect, from_config, from_json, from_profile

ASSEMBLED = frozenset({"autodetect", "from_config", "from_json", "from_profile"})
"""The names re-exported from the assembly (``poppy_core.assembly.build``)."""


def __getattr__(name: str) -> Any:
    """The assembly's builders, imported when first asked for (the room sits below them)."""
    if name in ASSEMBLED:
        import poppy_core.assembly

        return getattr(poppy_core.assembly, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
