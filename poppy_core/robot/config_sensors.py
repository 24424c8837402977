"""The config's ``sensors`` section as pydantic models: every problem at once.

The leaf does not validate: ``SensorEntry.spec`` hands ``poppy_core.sensors`` a plain
``SensorSpec`` (the section's form is in ``poppy_core.sensors.config``).
"""

from __future__ import annotations

import ipaddress
from collections.abc import Collection, Mapping
from typing import Annotated, Any, Literal

from pydantic import (
    AfterValidator,
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    Strict,
    model_validator,
)
from pydantic_core import PydanticCustomError

from poppy_core.errors import ConfigError, SensorError
from poppy_core.robot.config_format import config_error
from poppy_core.robot.config_sections import Name, Positive, non_empty
from poppy_core.sensors.blobs import check_filters
from poppy_core.sensors.camera import CameraCalibration, check_resolution
from poppy_core.sensors.config import (
    CAMERA_TYPES,
    DEVICE_TYPES,
    NOT_YET,
    OPTITRACK_TYPES,
    SUPPORTED_TYPES,
    SensorSpec,
)
from poppy_core.sensors.faces import MAX_FACE_PX, MIN_FACE_PX
from poppy_core.sensors.markers import FAMILIES
from poppy_core.sensors.optitrack import MULTICAST_GROUP

NETWORK_TYPES = ("KinectSensor", *OPTITRACK_TYPES)
"""Sensors whose integer ``port`` is a TCP or UDP port (the others' is a serial device)."""
SERVER_PORT_TYPES = ("KinectSensor", "OptiBridgeClient")
"""Their ``port`` is required: the server's TCP port."""
VRPN_PORT = 3883


def _sensor_type(value: str) -> str:
    if value in NOT_YET:
        raise PydanticCustomError(
            "sensor_type",
            "{kind} sensors are not supported yet (poppy drives {known}): remove this sensor "
            "from the config",
            {"kind": NOT_YET[value], "known": ", ".join(SUPPORTED_TYPES)},
        )
    if value not in SUPPORTED_TYPES:
        raise PydanticCustomError(
            "sensor_type",
            "unknown sensor type (one of {known})",
            {"known": ", ".join(SUPPORTED_TYPES)},
        )
    return value


def _resolution(value: Any) -> Any:
    try:
        return list(check_resolution(value, ""))
    except SensorError:
        raise PydanticCustomError("resolution", "must be [width, height] in pixels") from None


def _calibration(value: Any) -> Any:
    try:
        CameraCalibration.from_config(value, "")
    except SensorError as exc:
        raise PydanticCustomError("calibration", "{why}", {"why": _reason(exc)}) from None
    return value


def _families(value: list[str]) -> list[str]:
    if not value or set(value) - set(FAMILIES):
        raise PydanticCustomError(
            "families", "must be a list of {known}", {"known": ", ".join(FAMILIES)}
        )
    return value


def _min_size(value: int) -> int:
    if not MIN_FACE_PX <= value <= MAX_FACE_PX:
        raise PydanticCustomError(
            "min_size", "must be {low}-{high} pixels", {"low": MIN_FACE_PX, "high": MAX_FACE_PX}
        )
    return value


def _filters(value: dict[str, Any]) -> dict[str, Any]:
    try:
        check_filters(value)
    except SensorError as exc:
        raise PydanticCustomError("filters", "{why}", {"why": _reason(exc)}) from None
    return value


def _min_radius(value: int) -> int:
    if value < 1:
        raise PydanticCustomError("min_radius", "must be at least 1 pixel")
    return value


def _baud(value: int) -> int:
    if value <= 0:
        raise PydanticCustomError("baud", "must be a positive baud rate such as 115200")
    return value


def _bus_number(value: int) -> int:
    if value < 0:
        raise PydanticCustomError("i2c_pin", "must be an I2C bus number (1 is /dev/i2c-1)")
    return value


def _i2c_address(value: int) -> int:
    if not 0x03 <= value <= 0x7F:
        raise PydanticCustomError("address", "must be a 7-bit I2C address (112 is 0x70)")
    return value


def _tcp_port(value: int) -> int:
    if not 0 < value < 65536:
        raise PydanticCustomError("port", "must be a port number (1-65535)")
    return value


def _ipv4(value: str) -> str:
    try:
        ipaddress.IPv4Address(value)
    except ValueError:
        raise PydanticCustomError("ipv4", "must be an IPv4 address such as 192.168.1.10") from None
    return value


def _multicast_group(value: str) -> str:
    if not ipaddress.IPv4Address(_ipv4(value)).is_multicast:
        raise PydanticCustomError(
            "multicast",
            "must be a multicast group such as 239.255.42.99, or false for unicast",
        )
    return value


def _reason(exc: Exception) -> str:
    return str(exc).split(": ", 1)[-1]


MarkerIds = Annotated[
    list[Annotated[int, Strict()]],
    BeforeValidator(lambda v: v if isinstance(v, list) else [v]),
    Field(min_length=1),
]


class SensorEntry(BaseModel):
    """One sensor (pypot's keys and poppy's); unknown keys are kept as they are."""

    model_config = ConfigDict(extra="allow")

    type: Annotated[Name, AfterValidator(_sensor_type)]
    fps: Positive | None = None
    freq: Positive | None = None
    index: Annotated[int, Strict()] | Name | None = None
    device: Annotated[int, Strict()] | Name | None = None
    resolution: Annotated[Any, AfterValidator(_resolution)] = None
    calibration: Annotated[Any, AfterValidator(_calibration)] = None
    sim_camera: Name | None = None
    sim_body: Name | None = None
    cameras: list[Name] | None = None
    camera: Name | None = None
    python: Annotated[Name, AfterValidator(non_empty)] | None = None
    cards: dict[Name, MarkerIds] = Field(default_factory=dict)
    dictionary: Name | None = None
    marker_size: Positive | None = None
    families: Annotated[list[Name], AfterValidator(_families)] | None = None
    min_size: Annotated[Annotated[int, Strict()], AfterValidator(_min_size)] | None = None
    cascade: Annotated[Name, AfterValidator(non_empty)] | None = None
    filters: Annotated[dict[str, Any], AfterValidator(_filters)] | None = None
    min_radius: Annotated[Annotated[int, Strict()], AfterValidator(_min_radius)] | None = None
    sync_freq: Positive | None = None
    port: Annotated[Name, AfterValidator(non_empty)] | Annotated[int, Strict()] | None = None
    addr: Annotated[Name, AfterValidator(non_empty)] | None = None
    baud: Annotated[Annotated[int, Strict()], AfterValidator(_baud)] | None = None
    gpio_data: Annotated[int, Strict()] | Name | None = None
    gpio_vcc: Annotated[int, Strict()] | Name | None = None
    i2c_pin: Annotated[Annotated[int, Strict()], AfterValidator(_bus_number)] | None = None
    address: Annotated[Annotated[int, Strict()], AfterValidator(_i2c_address)] | None = None
    obj_names: Annotated[list[Name], Field(min_length=1)] | None = None
    data_port: Annotated[Annotated[int, Strict()], AfterValidator(_tcp_port)] | None = None
    multicast: Annotated[Name, AfterValidator(_multicast_group)] | Literal[False] | None = None
    local_addr: Annotated[Name, AfterValidator(_ipv4)] | None = None
    bridge_host: Annotated[Name, AfterValidator(non_empty)] | None = None
    bridge_port: Annotated[Annotated[int, Strict()], AfterValidator(_tcp_port)] | None = None

    @model_validator(mode="after")
    def _device_keys(self) -> SensorEntry:
        needed = {
            "ArduinoSensor": "port",
            "ContactSensor": "gpio_data",
            "SonarSensor": "i2c_pin",
            "RazorIMU": "port",
            "BlobDetector": "filters",
            "BNO055": "i2c_pin",
            "KinectSensor": "addr",
            "OptiTrackClient": "addr",
            "OptiBridgeServer": "addr",
            "OptiBridgeClient": "addr",
        }
        keys = [needed[self.type]] if self.type in needed else []
        if self.type in OPTITRACK_TYPES:
            keys.append("obj_names")
        if self.type == "OptiBridgeServer":
            keys += ["bridge_host", "bridge_port"]
        for key in keys:
            if getattr(self, key) is None:
                raise PydanticCustomError(
                    "device",
                    "{kind} needs its '{key}' key (as in pypot's config)",
                    {"kind": self.type, "key": key},
                )
        self._check_port()
        return self

    def _check_port(self) -> None:
        """An integer port for the network sensors, a serial device for the others."""
        number = self.port if isinstance(self.port, int) else None
        valid = number is not None and 0 < number < 65536
        if self.type in SERVER_PORT_TYPES and not valid:
            raise PydanticCustomError(
                "port",
                "{kind} needs its 'port': the server's TCP port (1-65535)",
                {"kind": self.type},
            )
        if self.type in OPTITRACK_TYPES and self.type not in SERVER_PORT_TYPES:
            if self.port is not None and not valid:
                raise PydanticCustomError(
                    "port", "must be Motive's NatNet command port (1-65535, 1510 by default)"
                )
            if self.port == VRPN_PORT:
                raise PydanticCustomError(
                    "port",
                    "3883 is VRPN's port (pypot's old wire); poppy reads Motive's NatNet "
                    "stream: give its command port (1510 by default) or leave 'port' out",
                )
        if self.type not in NETWORK_TYPES and number is not None:
            raise PydanticCustomError("port", "'port' must be a serial device such as /dev/ttyACM0")

    def spec(self, name: str) -> SensorSpec:
        """The plain entry the sensors leaf builds from."""
        given: dict[str, Any] = {
            "rate_hz": self.fps if self.type in CAMERA_TYPES else self.freq,
            "resolution": tuple(self.resolution) if self.resolution is not None else None,
            "calibration": (
                CameraCalibration.from_config(self.calibration, name)
                if self.calibration is not None
                else None
            ),
            "source": next((s for s in (self.index, self.device) if s is not None), 0),
            "sim_camera": self.sim_camera or name,
            "sim_body": self.sim_body,
            "cameras": (self.camera,) if self.camera else tuple(self.cameras or ()),
            "python": self.python,
            "cards": {card: list(ids) for card, ids in self.cards.items()},
            "dictionary": self.dictionary,
            "marker_size": self.marker_size,
            "families": tuple(self.families) if self.families is not None else None,
            "min_size": self.min_size,
            "cascade": self.cascade,
            "filters": check_filters(self.filters, name) if self.filters else None,
            "min_radius": self.min_radius,
            "port": self.port if isinstance(self.port, str) else None,
            "tcp_port": self.port if isinstance(self.port, int) else None,
            "addr": self.addr,
            "baud": self.baud,
            "gpio_data": self.gpio_data,
            "gpio_vcc": self.gpio_vcc,
            "i2c_pin": self.i2c_pin,
            "address": self.address,
            "obj_names": tuple(self.obj_names) if self.obj_names is not None else None,
            "data_port": self.data_port,
            "multicast": None if self.multicast is False else (self.multicast or MULTICAST_GROUP),
            "local_addr": self.local_addr,
            "bridge_host": self.bridge_host,
            "bridge_port": self.bridge_port,
        }
        if self.type in DEVICE_TYPES:
            given["rate_hz"] = self.sync_freq or self.freq
        keep = {"rate_hz", "resolution", "calibration", "cascade", "gpio_vcc", "multicast"}
        return SensorSpec(
            name, self.type, **{k: v for k, v in given.items() if v is not None or k in keep}
        )


def sensor_specs(sensors: Mapping[str, SensorEntry]) -> list[SensorSpec]:
    """The plain entries of a checked section, in its order."""
    return [entry.spec(name) for name, entry in sensors.items()]


def sensor_problems(
    sensors: Mapping[str, Any], taken: Collection[str], source: str
) -> list[ConfigError]:
    """Every problem across the section's entries: a detector reading no camera, a name clash.

    Args:
        sensors: the section, raw or validated (entries that are not mappings are skipped).
        taken: the names of the motors and groups.
        source: the file name (or label) for messages.
    """
    problems: list[ConfigError] = []

    def kind(entry: Any) -> Any:
        return (
            entry.type
            if isinstance(entry, SensorEntry)
            else (entry.get("type") if isinstance(entry, Mapping) else None)
        )

    for name, entry in sensors.items():
        if name in taken:
            problems.append(
                config_error(
                    source,
                    f"sensors.{name}",
                    name,
                    f"sensor {name!r} has the name of a motor or group",
                    show_value=False,
                )
            )
        if kind(entry) not in ("MarkerDetector", "FaceDetector", "PoseSkeleton"):
            continue
        cameras = entry.cameras if isinstance(entry, SensorEntry) else entry.get("cameras")
        field = "cameras"
        if kind(entry) == "PoseSkeleton":
            camera = entry.camera if isinstance(entry, SensorEntry) else entry.get("camera")
            if camera is not None or not isinstance(cameras, list) or len(cameras) != 1:
                cameras, field = [camera], "camera"
                if not isinstance(camera, str) or not camera:
                    problems.append(
                        config_error(
                            source,
                            f"sensors.{name}.camera",
                            camera,
                            "must name the camera sensor it looks through",
                        )
                    )
                    continue
        if not isinstance(cameras, list) or not cameras:
            problems.append(
                config_error(
                    source, f"sensors.{name}.cameras", cameras, "must list camera sensor names"
                )
            )
            continue
        for camera in cameras:
            if not isinstance(camera, str) or kind(sensors.get(camera)) not in CAMERA_TYPES:
                problems.append(
                    config_error(
                        source,
                        f"sensors.{name}.{field}",
                        cameras if field == "cameras" else camera,
                        f"{camera!r} is not a camera here",
                    )
                )
                break
    return problems


__all__ = [
    "SensorEntry",
    "sensor_problems",
    "sensor_specs",
]
