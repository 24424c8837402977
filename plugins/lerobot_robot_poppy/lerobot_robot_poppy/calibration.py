"""LeRobot's calibration file of a Poppy robot, and poppy's config it maps to.

LeRobot keeps a calibration per robot id in ``$HF_LEROBOT_CALIBRATION/robots/TYPE/ID.json``:
motor -> ``MotorCalibration(id, drive_mode, homing_offset, range_min, range_max)``, in the
servo's position ticks. Poppy keeps the same facts in its config, in degrees: a motor's
``orientation`` (drive_mode 0 direct, 1 indirect), ``offset`` (the user frame is
``sign * motor_angle - offset``) and ``angle_limit`` (motor frame). XL-320 and AX-12 have no
homing-offset register, and poppy writes none to the MX either: the offset is applied on the
host, by poppy, on every read and goal. The ticks are the servo's position register's
(XL-320/AX-12 1024 over 300°, MX 4096 over 360°), from poppy's register tables.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any

from lerobot.motors import MotorCalibration


def _position(model: str) -> Any:
    from poppy_core.models import model_by_name

    return model_by_name(model).register("goal_position")


def _ticks(register: Any, degrees: float) -> int:
    """``degrees`` (motor frame) as the register's raw position (150° of an XL-320 is 1024,
    one past the register's top: a limit, never a goal)."""
    return round((degrees - float(register.to_si(0))) / _step(register))


def _step(register: Any) -> float:
    return float(register.to_si(1)) - float(register.to_si(0))


def from_poppy(config: Any, motors: Iterable[str]) -> dict[str, MotorCalibration]:
    """LeRobot's calibration of ``motors`` from a poppy ``RobotConfig``."""
    out: dict[str, MotorCalibration] = {}
    for name in motors:
        entry = config.motors[name]
        register = _position(entry.type)
        low, high = entry.angle_limit
        out[name] = MotorCalibration(
            id=entry.id,
            drive_mode=0 if entry.orientation == "direct" else 1,
            homing_offset=round(entry.offset / _step(register)),
            range_min=_ticks(register, low),
            range_max=_ticks(register, high),
        )
    return out


def apply(config: Any, calibration: Mapping[str, MotorCalibration]) -> Any:
    """``config`` with the orientations, offsets and limits of LeRobot's ``calibration``.

    A value that rounds to the config's own (an offset of 90° is 307.2 ticks of an XL-320)
    keeps the config's exact degrees: reading a file written by :func:`from_poppy` changes
    nothing.

    Raises:
        ValueError: a motor the config lacks, or one whose ID differs (a file of another robot).
    """
    from poppy_core.robot import RobotConfig

    data = config.to_dict()
    for name, cal in calibration.items():
        entry = config.motors.get(name)
        if entry is None:
            raise ValueError(
                f"the calibration names a motor {name!r} this robot lacks "
                f"(motors: {', '.join(config.motors)}): is it another robot's file?"
            )
        if entry.id != cal.id:
            raise ValueError(
                f"the calibration gives {name} ID {cal.id}, the robot's is {entry.id}: "
                "is it another robot's file?"
            )
        register = _position(entry.type)
        mine = from_poppy(config, [name])[name]
        out = data["motors"][name]
        out["orientation"] = "direct" if cal.drive_mode == 0 else "indirect"
        if cal.homing_offset != mine.homing_offset:
            out["offset"] = cal.homing_offset * _step(register)
        if (cal.range_min, cal.range_max) != (mine.range_min, mine.range_max):
            zero, step = float(register.to_si(0)), _step(register)
            limits = sorted(zero + t * step for t in (cal.range_min, cal.range_max))
            out["angle_limit"] = limits
    return RobotConfig.from_dict(data, source="LeRobot calibration").with_folder(config.folder)
