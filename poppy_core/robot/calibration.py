"""Calibration data: a creature's reference posture, each joint's zero and range, the profile.

A profile may hold a ``calibration`` section::

    calibration:
      posture:                         # the reference posture (shipped profiles have one)
        description: All joints at 0°: the arm stands straight up...
        image: reference.png           # optional, relative to the profile's folder
        positions: {m2: 0.0}           # user-frame angles of the posture (others: 0°)
      calibrated: '2026-05-01T10:00:00+00:00'   # written by `poppy calibrate`
      from: ergo-jr
      motors:                          # as read, in the motor frame (degrees)
        m1: {zero: 1.2, range: [-148.0, 147.5]}

The arithmetic follows ``Motor``'s frames (``user = s * motor - offset``): a joint read ``z`` in
the motor frame while the robot is in the posture, where it should read ``p``, gets
``offset = s * z - p``; the range read by hand becomes ``angle_limit`` in the user frame, never
wider than what the servo's position registers can hold.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from poppy_core.errors import ConfigError
from poppy_core.models import model_by_name
from poppy_core.robot.config import RobotConfig

SECTION = "calibration"
DEFAULT_POSTURE = (
    "Every joint at its zero: the position the robot was assembled in (each horn's mark facing "
    "its motor's mark)."
)


@dataclass(frozen=True)
class ReferencePosture:
    """The posture the robot is put in to record each joint's zero.

    Attributes:
        description: what the posture looks like, for people.
        image: a picture of it (a file), or None.
        positions: user-frame degrees each joint reads in it (joints not listed: 0°).
    """

    description: str = DEFAULT_POSTURE
    image: Path | None = None
    positions: Mapping[str, float] = field(default_factory=dict)

    def angle(self, motor: str) -> float:
        """What ``motor`` should read in the posture (degrees, user frame)."""
        return float(self.positions.get(motor, 0.0))

    def to_dict(self) -> dict[str, Any]:
        """The ``calibration.posture`` section."""
        data: dict[str, Any] = {"description": self.description}
        if self.image is not None:
            data["image"] = self.image.name
        if self.positions:
            data["positions"] = dict(self.positions)
        return data


@dataclass(frozen=True)
class JointCalibration:
    """What was read of one joint: its zero and the range it was moved through.

    Attributes:
        motor: the motor's name.
        zero: motor-frame degrees read in the reference posture.
        posture: user-frame degrees it should read there.
        range: motor-frame (min, max) reached by hand, or None (keep the previous limits).
    """

    motor: str
    zero: float
    posture: float = 0.0
    range: tuple[float, float] | None = None

    def offset(self, orientation: str) -> float:
        """The config's ``offset``: ``s * zero - posture``."""
        return _sign(orientation) * self.zero - self.posture

    def angle_limit(
        self, orientation: str, servo_range: tuple[float, float]
    ) -> tuple[float, float] | None:
        """The range in the user frame, kept inside the servo's own (motor frame) range.

        Returns:
            (min, max), or None when no range was recorded or it is empty inside the servo's.
        """
        if self.range is None:
            return None
        low = max(min(self.range), servo_range[0])
        high = min(max(self.range), servo_range[1])
        if not low < high:
            return None
        sign, offset = _sign(orientation), self.offset(orientation)
        ends = sorted(_degrees(sign * value - offset) for value in (low, high))
        return (ends[0], ends[1]) if ends[0] < ends[1] else None


@dataclass(frozen=True)
class Calibration:
    """A calibration of some joints of a robot (``CalibrationSession.run`` makes one)."""

    joints: Mapping[str, JointCalibration]
    posture: ReferencePosture = field(default_factory=ReferencePosture)
    created: str = field(default_factory=lambda: datetime.now(UTC).isoformat(timespec="seconds"))

    def changes(self, config: RobotConfig) -> dict[str, dict[str, Any]]:
        """Motor -> its ``offset`` and ``angle_limit`` before and after (for a review table)."""
        out: dict[str, dict[str, Any]] = {}
        for name, joint in self.joints.items():
            entry = config.motors[name]
            limit = joint.angle_limit(entry.orientation, servo_range(entry.type))
            out[name] = {
                "offset": (entry.offset, _degrees(joint.offset(entry.orientation))),
                "angle_limit": (tuple(entry.angle_limit), limit or tuple(entry.angle_limit)),
                "range_recorded": joint.range is not None,
            }
        return out

    def apply(self, config: RobotConfig, name: str | None = None) -> RobotConfig:
        """``config`` with the joints' offsets and limits, and this calibration recorded.

        Args:
            config: the robot's config (its other motors are kept as they are).
            name: the profile name to give it (None keeps the header's).

        Raises:
            ConfigError: a joint the config does not have.
        """
        data = config.to_dict()
        base = config.profile.name if config.profile is not None else ""
        section = dict(data.get(SECTION) or {})
        recorded = dict(section.get("motors") or {})
        for motor, joint in self.joints.items():
            entry = config.motors.get(motor)
            if entry is None:
                raise ConfigError(f"the config has no motor {motor!r}", field=f"motors.{motor}")
            out = data["motors"][motor]
            out["offset"] = _degrees(joint.offset(entry.orientation))
            limit = joint.angle_limit(entry.orientation, servo_range(entry.type))
            if limit is not None:
                out["angle_limit"] = list(limit)
            record: dict[str, Any] = {"zero": round(joint.zero, 3)}
            previous = recorded.get(motor)
            if joint.range is not None:
                record["range"] = [round(min(joint.range), 3), round(max(joint.range), 3)]
            elif isinstance(previous, dict) and "range" in previous:
                record["range"] = previous["range"]
            recorded[motor] = record
        section.update(
            posture=self.posture.to_dict(),
            calibrated=self.created,
            motors=recorded,
        )
        section.setdefault("from", base)
        data[SECTION] = section
        header = dict(data.get("profile") or {"name": name or base or "robot"})
        if name is not None:
            header["name"] = name
        header.setdefault("kind", base)
        data["profile"] = header
        return RobotConfig.from_dict(data, source="calibration").with_folder(config.folder)


def _sign(orientation: str) -> float:
    return 1.0 if orientation == "direct" else -1.0


def _degrees(value: float) -> float:
    """Rounded to 0.01° (and -0.0 written 0.0)."""
    return round(value, 2) + 0.0


def servo_range(model: str) -> tuple[float, float]:
    """The motor-frame range a servo model's position limit registers hold (AX: -150..149.7°)."""
    register = model_by_name(model).register("min_position_limit")
    ends = sorted(float(register.to_si(raw)) for raw in (register.min_raw, register.max_raw))
    return ends[0], ends[1]


def reference_posture(config: RobotConfig) -> ReferencePosture:
    """The config's reference posture (``calibration.posture``; every joint at 0° if none).

    Raises:
        ConfigError: a malformed section.
    """
    section = (config.model_extra or {}).get(SECTION)
    if section is None:
        return ReferencePosture()
    where = f"{SECTION}.posture"
    if not isinstance(section, dict):
        raise ConfigError(f"{SECTION} must be a mapping", field=SECTION)
    posture = section.get("posture") or {}
    if not isinstance(posture, dict):
        raise ConfigError(f"{where} must be a mapping", field=where)
    description = posture.get("description", DEFAULT_POSTURE)
    if not isinstance(description, str):
        raise ConfigError(f"{where}.description must be text", field=f"{where}.description")
    image = posture.get("image")
    if image is not None and not isinstance(image, str):
        raise ConfigError(f"{where}.image must be a file name", field=f"{where}.image")
    positions = posture.get("positions") or {}
    if not isinstance(positions, dict):
        raise ConfigError(f"{where}.positions must map motors to degrees", field=where)
    for motor, value in positions.items():
        if motor not in config.motors:
            raise ConfigError(f"{where}.positions: no motor {motor!r}", field=f"{where}.{motor}")
        number = isinstance(value, int | float) and not isinstance(value, bool)
        if not number or not math.isfinite(value):
            raise ConfigError(
                f"{where}.positions.{motor} must be a number of degrees",
                field=f"{where}.{motor}",
                value=value,
            )
    folder = config.folder
    picture = None
    if image is not None:
        picture = Path(image) if Path(image).is_absolute() or folder is None else folder / image
    return ReferencePosture(
        description.strip(), picture, {str(k): float(v) for k, v in positions.items()}
    )


def recorded_joints(config: RobotConfig) -> dict[str, dict[str, Any]]:
    """The joints a calibration recorded (``calibration.motors``), empty when uncalibrated."""
    section = (config.model_extra or {}).get(SECTION)
    motors = section.get("motors") if isinstance(section, dict) else None
    return {str(k): v for k, v in motors.items() if isinstance(v, dict)} if motors else {}


def calibrated_on(config: RobotConfig) -> str | None:
    """When the config was calibrated (``calibration.calibrated``), or None."""
    section = (config.model_extra or {}).get(SECTION)
    value = section.get("calibrated") if isinstance(section, dict) else None
    return str(value) if value else None


def check_motors(config: RobotConfig, motors: Iterable[str] | None) -> list[str]:
    """The motors to calibrate (every motor but wheels when None), checked against the config.

    Raises:
        ConfigError: an unknown motor or group, or a wheel (it has no range to record).
    """
    if motors is None:
        return [
            n
            for n, m in config.motors.items()
            if not m.wheel_mode and config.controller_of(n) is not None
        ]
    chosen: list[str] = []
    for item in motors:
        if item not in config.motors and item not in config.motorgroups:
            groups = ", ".join(config.motorgroups) or "none"
            raise ConfigError(
                f"no motor or group {item!r} (motors: {', '.join(config.motors)}; "
                f"groups: {groups})",
                field="motors",
                value=item,
            )
        names = config.resolve_group(item)  # a motor name gives that motor alone
        for motor in names:
            if config.motors[motor].wheel_mode:
                raise ConfigError(
                    f"{motor} is a wheel: it has no range to calibrate", field=f"motors.{motor}"
                )
            if motor not in chosen:
                chosen.append(motor)
    if not chosen:
        raise ConfigError("no motor to calibrate", field="motors")
    return chosen
