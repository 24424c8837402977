"""Robot configuration model (pydantic v2), compatible with pypot's JSON robot configs."""

from __future__ import annotations

import difflib
from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    Strict,
    ValidationError,
    ValidationInfo,
    field_validator,
    model_validator,
)
from pydantic_core import PydanticCustomError

from poppy_core.errors import ConfigError, UnknownModelError
from poppy_core.models import ALL_MODELS, model_by_name
from poppy_core.robot.config_checks import (
    CheckView,
    check_config,
    expand,
    whole_config_problems,
)
from poppy_core.robot.config_format import DEFAULT_SOURCE, config_error, validation_problems
from poppy_core.robot.config_sections import KinematicsSection
from poppy_core.robot.config_sensors import SensorEntry, sensor_problems
from poppy_core.robot.frames import user_limits

Degrees = Annotated[float, Strict(), Field(allow_inf_nan=False)]
"""A finite angle in degrees (ints accepted, strings and booleans refused)."""
Finite = Annotated[float, Strict(), Field(allow_inf_nan=False)]
"""A finite number (ints accepted, strings and booleans refused)."""
Name = Annotated[str, Strict()]

# e-manual (AX/MX/X series): Return Delay Time is stored in 2 µs units, raw 0-254 → 0-508 µs.
MAX_RETURN_DELAY_US = 508
# e-manual: IDs 0-253 address single motors; 254 (0xFE) is the broadcast ID.
MAX_MOTOR_ID = 253
DEFAULT_BAUDRATE = 1_000_000


class ProfileHeader(BaseModel):
    """The small header a profile YAML carries under its ``profile:`` key."""

    model_config = ConfigDict(extra="allow")

    name: Name
    description: Name = ""
    kind: Name = ""
    source: Name = ""


class ControllerConfig(BaseModel):
    """One bus: a serial port, a protocol, a baud rate and the motors attached to it."""

    model_config = ConfigDict(extra="allow")

    port: Name = "auto"
    protocol: Annotated[int, Strict()] = 1
    baudrate: Annotated[int, Strict()] = DEFAULT_BAUDRATE
    sync_read: Annotated[bool, Strict()] = False
    attached_motors: list[Name]
    syncloop: Name = "BaseDxlController"

    @field_validator("protocol")
    @classmethod
    def _check_protocol(cls, value: int) -> int:
        if value not in (1, 2):
            raise PydanticCustomError("protocol", "must be 1 or 2")
        return value

    @field_validator("baudrate")
    @classmethod
    def _check_baudrate(cls, value: int) -> int:
        if value <= 0:
            raise PydanticCustomError("baudrate", "must be a positive number of bits/s")
        return value


def _closest_models(name: str) -> tuple[list[str], list[str]]:
    """Known model names and the ones closest to ``name``."""
    known = sorted({model.name for model in ALL_MODELS})
    closest = difflib.get_close_matches(name.upper(), [k.upper() for k in known], n=2, cutoff=0.5)
    by_upper = {k.upper(): k for k in known}
    return known, [by_upper[c] for c in closest]


def _check_pair_shape(value: Any, size: int, shape: str) -> Any:
    if not isinstance(value, (list, tuple)) or len(value) != size:
        raise PydanticCustomError("shape", "must be {shape}", {"shape": shape})
    return value


class MotorConfig(BaseModel):
    """One motor: its ID, servo model, mounting (orientation, offset) and angle limits.

    ``angle_limit`` is in the motor frame, as in pypot: the servo's own angles, the values its
    EEPROM limits hold (``user_angle_limit`` gives them in the user frame).
    """

    model_config = ConfigDict(extra="allow")

    id: Annotated[int, Strict()]
    type: Name
    orientation: Literal["direct", "indirect"] = "direct"
    offset: Degrees = 0.0
    angle_limit: tuple[Degrees, Degrees]
    return_delay_time: Annotated[int, Strict()] | None = None
    max_torque: Finite | None = None
    pid: tuple[Finite, Finite, Finite] | None = None
    wheel_mode: Annotated[bool, Strict()] = False

    @field_validator("id")
    @classmethod
    def _check_id(cls, value: int) -> int:
        if not 0 <= value <= MAX_MOTOR_ID:
            raise PydanticCustomError(
                "motor_id", "ID must be in 0-{top} (254 is broadcast)", {"top": MAX_MOTOR_ID}
            )
        return value

    @field_validator("type")
    @classmethod
    def _check_type(cls, value: str) -> str:
        try:
            model_by_name(value)
        except UnknownModelError:
            known, closest = _closest_models(value)
            hint = f" (did you mean {' or '.join(closest)}?)" if closest else ""
            raise PydanticCustomError(
                "motor_type",
                "unknown motor type{hint}; known: {known}",
                {"hint": hint, "known": ", ".join(known)},
            ) from None
        return value

    @field_validator("angle_limit", mode="before")
    @classmethod
    def _check_limit_shape(cls, value: Any) -> Any:
        return _check_pair_shape(value, 2, "[min, max] in degrees")

    @field_validator("angle_limit")
    @classmethod
    def _check_limit_order(cls, value: tuple[float, float]) -> tuple[float, float]:
        if value[0] >= value[1]:
            raise PydanticCustomError("angle_limit", "min must be below max")
        return value

    @property
    def user_angle_limit(self) -> tuple[float, float]:
        """``angle_limit`` in the user frame (orientation and offset applied), (min, max)."""
        return user_limits(self.angle_limit, self.orientation, self.offset)

    @field_validator("pid", mode="before")
    @classmethod
    def _check_pid_shape(cls, value: Any) -> Any:
        return value if value is None else _check_pair_shape(value, 3, "[p, i, d]")

    @field_validator("return_delay_time")
    @classmethod
    def _check_delay(cls, value: int | None) -> int | None:
        if value is not None and not 0 <= value <= MAX_RETURN_DELAY_US:
            raise PydanticCustomError(
                "delay", "must be in 0-{top} µs", {"top": MAX_RETURN_DELAY_US}
            )
        return value

    @field_validator("max_torque")
    @classmethod
    def _check_torque(cls, value: float | None) -> float | None:
        if value is not None and not 0.0 <= value <= 100.0:
            raise PydanticCustomError("torque", "must be a percentage in 0-100")
        return value


class RobotConfig(BaseModel):
    """A whole robot: controllers (buses), motor groups, motors and sensors.

    Build it with :meth:`from_dict` (or :func:`poppy_core.robot.load_config`) to get
    :class:`~poppy_core.errors.ConfigError` on bad input; unknown keys are kept as they are.
    """

    model_config = ConfigDict(extra="allow")

    profile: ProfileHeader | None = None
    controllers: dict[Name, ControllerConfig]
    motorgroups: dict[Name, list[Name]] = Field(default_factory=dict)
    motors: dict[Name, MotorConfig]
    sensors: dict[Name, SensorEntry] = Field(default_factory=dict)
    kinematics: KinematicsSection | None = None

    @property
    def folder(self) -> Path | None:
        """The folder of the file this config was read from (relative file names start there)."""
        folder = self.__dict__.get("_source_folder")
        return folder if isinstance(folder, Path) else None

    def with_folder(self, folder: Path | None) -> RobotConfig:
        """This config, remembering ``folder`` as the one it was read from; returns itself.

        Kept outside the model's fields and private attributes, so that two configs with the
        same content compare equal wherever they were read from.
        """
        object.__setattr__(self, "_source_folder", folder)
        return self

    @model_validator(mode="after")
    def _check_whole(self, info: ValidationInfo) -> RobotConfig:
        context = info.context if isinstance(info.context, dict) else {}
        source = str(context.get("source", DEFAULT_SOURCE))
        check_config(self, source)
        problems = sensor_problems(self.sensors, {*self.motors, *self.motorgroups}, source)
        if problems:
            raise ConfigError.of_problems(problems)
        return self

    @classmethod
    def from_dict(cls, data: Any, source: str = DEFAULT_SOURCE) -> RobotConfig:
        """Validate a config dict (pypot JSON content or our YAML content).

        Args:
            data: The parsed document.
            source: A file name or label used in error messages.

        Returns:
            The validated config.

        Raises:
            ConfigError: With a one-line message naming the source, the field path, the value
                and the reason of the first problem; ``problems`` lists every problem found,
                each with its own one-line message.
        """
        if not isinstance(data, dict):
            raise config_error(
                source, "", data, "must be a mapping with controllers, motorgroups and motors"
            )
        try:
            return cls.model_validate(data, context={"source": source})
        except ValidationError as exc:
            problems = validation_problems(exc, source)
        # Fields failed: the checks across fields still run on what is readable, so that one
        # pass reports every problem (a duplicate ID and a reversed limit alike).
        view = CheckView.of_document(data)
        fields = {p.field for p in problems}
        if view is not None:
            problems += [p for p in whole_config_problems(view, source) if p.field not in fields]
        sensors = data.get("sensors")
        if isinstance(sensors, dict):
            taken = {*(data.get("motors") or {}), *(data.get("motorgroups") or {})}
            more = sensor_problems(sensors, taken, source)
            problems += [p for p in more if p.field not in fields]
        raise ConfigError.of_problems(problems) from None

    def to_dict(self) -> dict[str, Any]:
        """Our format as plain data (what the YAML writer dumps), profile header included."""
        data = self.model_dump(mode="json", exclude_unset=True)
        self._fill_pypot_required(data)
        return data

    def to_pypot_dict(self) -> dict[str, Any]:
        """The config as pypot expects it (no profile header; keys pypot requires always present).

        Returns:
            A JSON-ready dict; keys given in the source and unknown keys are kept.
        """
        data = self.to_dict()
        data.pop("profile", None)
        data.setdefault("motorgroups", {})
        return data

    def _fill_pypot_required(self, data: dict[str, Any]) -> None:
        for name, controller in self.controllers.items():
            out = data["controllers"][name]
            out.setdefault("port", controller.port)
            out.setdefault("sync_read", controller.sync_read)
            out.setdefault("attached_motors", list(controller.attached_motors))
        for name, motor in self.motors.items():
            out = data["motors"][name]
            out.setdefault("orientation", motor.orientation)
            out.setdefault("offset", motor.offset)

    def resolve_group(self, name: str) -> list[str]:
        """The motors a group names, nested groups flattened, in order, without repeats.

        Args:
            name: A group name (a motor name gives that motor alone).

        Returns:
            Motor names.

        Raises:
            ConfigError: When no motor or group has that name.
        """
        if name not in self.motorgroups and name not in self.motors:
            known = ", ".join(sorted(self.motorgroups)) or "none"
            raise config_error(
                DEFAULT_SOURCE,
                f"motorgroups.{name}",
                name,
                f"no such group (groups: {known})",
                show_value=False,
            )
        return expand([name], self.motors, self.motorgroups)

    def motors_of_controller(self, name: str) -> list[str]:
        """The motors attached to a controller, groups flattened, in order.

        Args:
            name: A controller name.

        Returns:
            Motor names.

        Raises:
            ConfigError: When there is no such controller.
        """
        controller = self.controllers.get(name)
        if controller is None:
            known = ", ".join(sorted(self.controllers))
            raise config_error(
                DEFAULT_SOURCE,
                f"controllers.{name}",
                name,
                f"no such controller (controllers: {known})",
                show_value=False,
            )
        return expand(controller.attached_motors, self.motors, self.motorgroups)

    def controller_of(self, motor: str) -> str | None:
        """The name of the controller a motor is attached to, or None when it is not attached."""
        for name in self.controllers:
            if motor in self.motors_of_controller(name):
                return name
        return None

    def unattached_motors(self) -> list[str]:
        """Motors defined under ``motors`` but attached to no controller (they are not driven)."""
        attached = {m for name in self.controllers for m in self.motors_of_controller(name)}
        return [name for name in self.motors if name not in attached]
