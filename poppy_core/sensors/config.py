"""Sensors from a config's ``sensors`` section (pypot's JSON form): checked, then built.

pypot's form: ``{"camera": {"type": "OpenCVCamera", "index": -1, "fps": 20.0, "resolution":
[640, 480]}, "marker_detector": {"type": "MarkerDetector", "cameras": ["camera"], "freq": 1.0,
"need_robot": true}}`` (poppy_ergo_jr.json). Keys poppy adds: ``calibration`` (camera),
``cards``, ``dictionary``, ``marker_size``, ``families`` (marker detector), ``sim_camera`` (the
MuJoCo camera a simulated robot renders for it; default: the sensor's name). A ``FaceDetector``
(pypot's: ``cameras``, ``freq``) takes ``min_size`` (pixels) and ``cascade`` (an LBP cascade XML).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from typing import Any

from poppy_core.checks import count
from poppy_core.errors import ArgumentError, SensorError
from poppy_core.sensors.base import Sensor
from poppy_core.sensors.camera import (
    DEFAULT_FPS,
    DEFAULT_RESOLUTION,
    Camera,
    CameraCalibration,
    DummyCamera,
    check_resolution,
)
from poppy_core.sensors.detector import DEFAULT_FREQ_HZ, MarkerDetector
from poppy_core.sensors.faces import (
    DEFAULT_FACE_FREQ_HZ,
    DEFAULT_MIN_SIZE_PX,
    MAX_FACE_PX,
    MIN_FACE_PX,
    FaceDetector,
)
from poppy_core.sensors.markers import DEFAULT_DICTIONARY, DEFAULT_MARKER_SIZE_M, FAMILIES

CAMERA_TYPES = ("OpenCVCamera", "DummyCamera")
DETECTOR_TYPES = ("MarkerDetector", "FaceDetector")
SUPPORTED_TYPES = (*CAMERA_TYPES, *DETECTOR_TYPES)
NOT_YET: dict[str, str] = {
    # pypot 5.0.2's pypot.sensor classes and the sensors the Poppy documentation names
    "KinectSensor": "Kinect",
    "OptiTrackClient": "OptiTrack",
    "OptiBridgeServer": "OptiTrack",
    "TrackedObject": "OptiTrack",
    "IMU": "IMU",
    "RazorIMU": "IMU",
    "ForceSensor": "force",
    "ContactSensor": "contact",
    "SonarSensor": "sonar",
    "ArduinoSensor": "Arduino",
    "BlobDetector": "blob detector",
}


class SensorProblem(Exception):
    """A bad entry of the section: the field path under ``sensors``, its value and why."""

    def __init__(self, field: str, value: Any, reason: str) -> None:
        super().__init__(f"{field}: {reason}")
        self.field = field
        self.value = value
        self.reason = reason


def _number(spec: Mapping[str, Any], key: str, default: float, name: str) -> float:
    value = spec.get(key, default)
    if isinstance(value, bool) or not isinstance(value, int | float) or not value > 0 or not (
        math.isfinite(value)
    ):
        raise SensorProblem(f"{name}.{key}", value, "must be a positive number")
    return float(value)


def _type(name: str, spec: Any) -> str:
    if not isinstance(spec, Mapping):
        raise SensorProblem(name, spec, "must be a mapping with a type")
    kind = spec.get("type")
    if kind in NOT_YET:
        raise SensorProblem(
            f"{name}.type",
            kind,
            f"{NOT_YET[kind]} sensors are not supported yet (poppy drives "
            f"{', '.join(SUPPORTED_TYPES)}): remove this sensor from the config",
        )
    if kind not in SUPPORTED_TYPES:
        raise SensorProblem(
            f"{name}.type", kind, f"unknown sensor type (one of {', '.join(SUPPORTED_TYPES)})"
        )
    return str(kind)


def _cards(name: str, value: Any) -> dict[str, list[int]]:
    if not isinstance(value, Mapping):
        raise SensorProblem(f"{name}.cards", value, "must map card names to marker ids")
    cards: dict[str, list[int]] = {}
    for card, ids in value.items():
        listed = ids if isinstance(ids, list) else [ids]
        if not listed or not all(isinstance(i, int) and not isinstance(i, bool) for i in listed):
            raise SensorProblem(f"{name}.cards.{card}", ids, "must be a marker id or a list")
        cards[str(card)] = [int(i) for i in listed]
    return cards


def check_section(section: Mapping[str, Any]) -> None:
    """Check every entry without opening anything.

    Raises:
        SensorProblem: the first bad entry (unknown or not yet supported type, bad value).
    """
    for name, spec in section.items():
        kind = _type(name, spec)
        _number(spec, "fps" if kind in CAMERA_TYPES else "freq", 1.0, name)
        if kind in CAMERA_TYPES:
            try:
                if "resolution" in spec:
                    check_resolution(spec["resolution"], name)
                if "calibration" in spec:
                    CameraCalibration.from_config(spec["calibration"], name)
            except SensorError as exc:
                raise SensorProblem(name, spec, str(exc).split(": ", 1)[-1]) from None
            continue
        cameras = spec.get("cameras")
        if not isinstance(cameras, list) or not cameras:
            raise SensorProblem(f"{name}.cameras", cameras, "must list camera sensor names")
        for camera in cameras:
            target = section.get(camera)
            if not isinstance(target, Mapping) or target.get("type") not in CAMERA_TYPES:
                raise SensorProblem(f"{name}.cameras", cameras, f"{camera!r} is not a camera here")
        if kind == "FaceDetector":
            _face_options(name, spec)
            continue
        _cards(name, spec.get("cards", {}))
        _number(spec, "marker_size", DEFAULT_MARKER_SIZE_M, name)
        families = spec.get("families", list(FAMILIES))
        if not isinstance(families, list) or not families or set(families) - set(FAMILIES):
            raise SensorProblem(f"{name}.families", families, f"a list of {', '.join(FAMILIES)}")


def _face_options(name: str, spec: Mapping[str, Any]) -> tuple[int, str | None]:
    size = spec.get("min_size", DEFAULT_MIN_SIZE_PX)
    try:
        size = count(size, MIN_FACE_PX, MAX_FACE_PX, "min_size")
    except ArgumentError as exc:
        raise SensorProblem(f"{name}.min_size", size, str(exc)) from None
    cascade = spec.get("cascade")
    if cascade is not None and (not isinstance(cascade, str) or not cascade):
        raise SensorProblem(f"{name}.cascade", cascade, "must be the path of an LBP cascade XML")
    return size, cascade


CameraMaker = Callable[[str, Mapping[str, Any]], Camera]
"""Makes the camera of one config entry (name, spec): real, dummy or simulated."""


def opencv_camera(name: str, spec: Mapping[str, Any]) -> Camera:
    """The camera an entry describes on real hardware (``OpenCVCamera`` opens its device).

    A camera is an accessory: one that cannot be opened now (unplugged, busy in another
    program) starts lost and is opened with backoff when it can be (``retry_open``).
    """
    resolution = spec.get("resolution")
    fps = float(spec.get("fps", DEFAULT_FPS))
    calibration = spec.get("calibration")
    cal = CameraCalibration.from_config(calibration, name) if calibration is not None else None
    if spec.get("type") == "DummyCamera":
        return DummyCamera(name, tuple(resolution or DEFAULT_RESOLUTION), fps)
    from poppy_core.sensors.opencv_camera import OpenCVCamera

    return OpenCVCamera(
        name,
        spec.get("index", spec.get("device", 0)),
        fps,
        tuple(resolution) if resolution is not None else None,
        calibration=cal,
        retry_open=True,
    )


def dummy_camera(name: str, spec: Mapping[str, Any]) -> Camera:
    """A blank camera for an entry (ideal simulation: there is no scene to see)."""
    resolution = spec.get("resolution") or DEFAULT_RESOLUTION
    return DummyCamera(name, (int(resolution[0]), int(resolution[1])),
                       float(spec.get("fps", DEFAULT_FPS)))  # fmt: skip


def build_sensors(
    section: Mapping[str, Any], make_camera: CameraMaker = opencv_camera
) -> dict[str, Sensor]:
    """The sensors of a checked section, cameras first; none started yet.

    Raises:
        SensorError: a sensor cannot be made: a bad camera index, face detection without
            scikit-image (the ones made so far are closed).
    """
    sensors: dict[str, Sensor] = {}
    try:
        for name, spec in section.items():
            if spec.get("type") in CAMERA_TYPES:
                sensors[name] = make_camera(name, spec)
        for name, spec in section.items():
            if spec.get("type") == "MarkerDetector":
                cameras = [sensors[c] for c in spec["cameras"]]
                sensors[name] = MarkerDetector(
                    name,
                    [c for c in cameras if isinstance(c, Camera)],
                    float(spec.get("freq", DEFAULT_FREQ_HZ)),
                    cards=_cards(name, spec.get("cards", {})),
                    dictionary=str(spec.get("dictionary", DEFAULT_DICTIONARY)),
                    marker_size=float(spec.get("marker_size", DEFAULT_MARKER_SIZE_M)),
                    families=tuple(spec.get("families", FAMILIES)),
                )
            elif spec.get("type") == "FaceDetector":
                min_size, cascade = _face_options(name, spec)
                sensors[name] = FaceDetector(
                    name,
                    [c for c in (sensors[c] for c in spec["cameras"]) if isinstance(c, Camera)],
                    float(spec.get("freq", DEFAULT_FACE_FREQ_HZ)),
                    min_size=min_size,
                    cascade=cascade,
                )
    except BaseException:
        for sensor in sensors.values():
            sensor.close()
        raise
    return {name: sensors[name] for name in section if name in sensors}
