"""Sensors from a config's ``sensors`` section (pypot's JSON form), built from checked entries.

pypot's form: ``{"camera": {"type": "OpenCVCamera", "index": -1, "fps": 20.0, "resolution":
[640, 480]}, "marker_detector": {"type": "MarkerDetector", "cameras": ["camera"], "freq": 1.0,
"need_robot": true}}`` (poppy_ergo_jr.json). Keys poppy adds: ``calibration`` (camera),
``cards``, ``dictionary``, ``marker_size``, ``families`` (marker detector), ``sim_camera`` (the
MuJoCo camera a simulated robot renders for it; default: the sensor's name). A ``FaceDetector``
(pypot's: ``cameras``, ``freq``) takes ``min_size`` (pixels) and ``cascade`` (an LBP cascade XML).
A ``BlobDetector`` (pypot's: ``cameras``, ``freq``, ``filters``) takes ``min_radius`` (pixels).
The device sensors take pypot's keys: ``ArduinoSensor`` ``port``, ``baud``, ``sync_freq``;
``ContactSensor`` ``gpio_data``, ``gpio_vcc``; ``SonarSensor`` ``i2c_pin``, ``address``,
``sync_freq``; ``KinectSensor`` ``addr``, ``port`` (the skeleton server's ZMQ port);
``OptiTrackClient`` ``addr`` (Motive's host), ``port`` (its NatNet command port, 1510),
``obj_names``, and poppy's ``data_port`` (1511), ``multicast`` (the group, 239.255.42.99;
``false``: unicast), ``local_addr`` (the interface to listen on, 0.0.0.0);
``OptiBridgeServer`` the same plus ``bridge_host``, ``bridge_port`` (its ZMQ PUB socket);
``OptiBridgeClient`` (pypot's ``optibridge.OptiTrackClient``) ``addr``, ``port``,
``obj_names``. A ``PoseSkeleton`` (a person's skeleton from a camera, MediaPipe Pose) takes
``camera`` (its camera's name; or ``cameras`` with one name), ``freq`` and ``python`` (an
interpreter with MediaPipe 0.10.21; default: the pose venv's). The
IMUs: ``RazorIMU`` ``port``, ``baud`` (57600), ``sync_freq``; ``BNO055`` ``i2c_pin``,
``address`` (0x28), ``sync_freq``; both take ``sim_body`` (the MuJoCo body a
simulated robot's IMU rides; default ``head``).
The section is checked where the rest of the config is (``poppy_core.robot.config_sensors``,
every problem at once); this leaf receives plain ``SensorSpec`` entries.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any

from poppy_core.errors import SensorError
from poppy_core.sensors.arduino import DEFAULT_BAUD, DEFAULT_SYNC_HZ, ArduinoSensor
from poppy_core.sensors.base import Sensor
from poppy_core.sensors.blobs import DEFAULT_BLOB_FREQ_HZ, DEFAULT_MIN_RADIUS_PX, BlobDetector
from poppy_core.sensors.bno055 import BNO055, DEFAULT_BNO055_ADDRESS, DEFAULT_BNO055_HZ
from poppy_core.sensors.camera import (
    DEFAULT_FPS,
    DEFAULT_RESOLUTION,
    Camera,
    CameraCalibration,
    DummyCamera,
)
from poppy_core.sensors.detector import DEFAULT_FREQ_HZ, MarkerDetector
from poppy_core.sensors.faces import (
    DEFAULT_FACE_FREQ_HZ,
    DEFAULT_MIN_SIZE_PX,
    FaceDetector,
)
from poppy_core.sensors.imu import RAZOR_BAUD, RAZOR_HZ, Imu, RazorIMU, StillIMU
from poppy_core.sensors.kinect import DEFAULT_KINECT_HZ, KinectSensor
from poppy_core.sensors.markers import DEFAULT_DICTIONARY, DEFAULT_MARKER_SIZE_M, FAMILIES
from poppy_core.sensors.optibridge import DEFAULT_BRIDGE_HZ, OptiBridgeClient, OptiBridgeServer
from poppy_core.sensors.optitrack import (
    COMMAND_PORT,
    DATA_PORT,
    DEFAULT_OPTITRACK_HZ,
    MULTICAST_GROUP,
    OptiTrackClient,
)
from poppy_core.sensors.pose import DEFAULT_POSE_FREQ_HZ, PoseSkeleton
from poppy_core.sensors.sonar import DEFAULT_ADDRESS, DEFAULT_SONAR_HZ, SonarSensor

CAMERA_TYPES = ("OpenCVCamera", "DummyCamera")
DETECTOR_TYPES = ("MarkerDetector", "FaceDetector", "BlobDetector", "PoseSkeleton")
IMU_TYPES = ("RazorIMU", "BNO055")
OPTITRACK_TYPES = ("OptiTrackClient", "OptiBridgeServer", "OptiBridgeClient")
DEVICE_TYPES = (
    "ArduinoSensor",
    "ContactSensor",
    "SonarSensor",
    "KinectSensor",
    *OPTITRACK_TYPES,
    *IMU_TYPES,
)
"""Sensors on their own device (a serial port, a GPIO pin, an I2C bus, a server), no camera."""
SUPPORTED_TYPES = (*CAMERA_TYPES, *DETECTOR_TYPES, *DEVICE_TYPES)
NOT_YET: dict[str, str] = {
    # pypot 5.0.2's pypot.sensor classes and the sensors the Poppy documentation names
    "ForceSensor": "force",
}


@dataclass(frozen=True)
class SensorSpec:
    """One entry of the section, already checked (``poppy_core.robot.config_sensors``).

    ``rate_hz`` is a camera's ``fps`` or a detector's ``freq`` (None: the kind's default);
    ``source`` a camera's ``index`` or ``device``; the rest as the module's docstring says.
    """

    name: str
    type: str
    rate_hz: float | None = None
    resolution: tuple[int, int] | None = None
    calibration: CameraCalibration | None = None
    source: int | str = 0
    sim_camera: str | None = None
    sim_body: str | None = None
    cameras: tuple[str, ...] = ()
    cards: Mapping[str, list[int]] = field(default_factory=dict)
    dictionary: str = DEFAULT_DICTIONARY
    marker_size: float = DEFAULT_MARKER_SIZE_M
    families: tuple[str, ...] = FAMILIES
    min_size: int = DEFAULT_MIN_SIZE_PX
    cascade: str | None = None
    filters: Mapping[str, tuple[int, int]] = field(default_factory=dict)
    min_radius: int = DEFAULT_MIN_RADIUS_PX
    port: str = ""
    addr: str = ""
    tcp_port: int = 0
    baud: int | None = None
    gpio_data: int | str = 0
    gpio_vcc: int | str | None = None
    i2c_pin: int = 1
    address: int | None = None
    obj_names: tuple[str, ...] = ()
    data_port: int = DATA_PORT
    multicast: str | None = MULTICAST_GROUP
    local_addr: str = "0.0.0.0"
    bridge_host: str = ""
    bridge_port: int = 0
    python: str | None = None

    @property
    def is_camera(self) -> bool:
        """Whether the entry is a camera (the others are detectors reading cameras)."""
        return self.type in CAMERA_TYPES

    @property
    def is_imu(self) -> bool:
        """Whether the entry is an IMU (simulated in a MuJoCo world)."""
        return self.type in IMU_TYPES

    @property
    def is_device(self) -> bool:
        """Whether the entry is a sensor on its own device (no camera read)."""
        return self.type in DEVICE_TYPES


CameraMaker = Callable[[SensorSpec], Camera]
"""Makes the camera of one config entry: real, dummy or simulated."""
ImuMaker = Callable[[SensorSpec], Imu]
"""Makes the IMU of one config entry: real (its device), still (ideal) or simulated."""


def opencv_camera(spec: SensorSpec) -> Camera:
    """The camera an entry describes on real hardware (``OpenCVCamera`` opens its device).

    A camera is an accessory: one that cannot be opened now (unplugged, busy in another
    program) starts lost and is opened with backoff when it can be (``retry_open``).
    """
    fps = spec.rate_hz or DEFAULT_FPS
    if spec.type == "DummyCamera":
        return DummyCamera(spec.name, spec.resolution or DEFAULT_RESOLUTION, fps)
    from poppy_core.sensors.opencv_capture import OpenCVCamera

    return OpenCVCamera(
        spec.name, spec.source, fps, spec.resolution, calibration=spec.calibration, retry_open=True
    )


def dummy_camera(spec: SensorSpec) -> Camera:
    """A blank camera for an entry (ideal simulation: there is no scene to see)."""
    return DummyCamera(
        spec.name, spec.resolution or DEFAULT_RESOLUTION, spec.rate_hz or DEFAULT_FPS
    )


def device_imu(spec: SensorSpec) -> Imu:
    """The IMU of an entry on its real device (opened on first use)."""
    if spec.type == "BNO055":
        address = spec.address or DEFAULT_BNO055_ADDRESS
        return BNO055(spec.name, spec.i2c_pin, address, spec.rate_hz or DEFAULT_BNO055_HZ)
    return RazorIMU(spec.name, spec.port, spec.baud or RAZOR_BAUD, spec.rate_hz or RAZOR_HZ)


def still_imu(spec: SensorSpec) -> Imu:
    """The IMU of an entry on a robot without physics (the ideal simulation): level, still."""
    return StillIMU(spec.name, spec.rate_hz or RAZOR_HZ)


def device_sensor(spec: SensorSpec) -> Sensor:
    """The sensor of an Arduino, contact or sonar entry (its device opens on first use;
    a contact sensor claims its pins now)."""
    if spec.type == "ArduinoSensor":
        baud = spec.baud or DEFAULT_BAUD
        return ArduinoSensor(spec.name, spec.port, baud, spec.rate_hz or DEFAULT_SYNC_HZ)
    if spec.type == "KinectSensor":
        return KinectSensor(spec.name, spec.addr, spec.tcp_port, spec.rate_hz or DEFAULT_KINECT_HZ)
    if spec.type in OPTITRACK_TYPES:
        return optitrack_sensor(spec)
    if spec.type == "SonarSensor":
        address = spec.address or DEFAULT_ADDRESS
        return SonarSensor(spec.name, spec.i2c_pin, address, spec.rate_hz or DEFAULT_SONAR_HZ)
    from poppy_core.sensors.contact import DEFAULT_CONTACT_HZ, ContactSensor

    return ContactSensor(
        spec.name, spec.gpio_data, spec.gpio_vcc, spec.rate_hz or DEFAULT_CONTACT_HZ
    )


def optitrack_sensor(spec: SensorSpec) -> Sensor:
    """The OptiTrack client, bridge server or bridge client of an entry.

    A bridge server starts at once: it serves other machines and nobody here reads it, so the
    first use that starts the other sensors would never come.
    """
    if spec.type == "OptiBridgeClient":
        rate = spec.rate_hz or DEFAULT_BRIDGE_HZ
        return OptiBridgeClient(spec.name, spec.addr, spec.tcp_port, spec.obj_names, rate)
    natnet: dict[str, Any] = {
        "data_port": spec.data_port,
        "multicast": spec.multicast,
        "local_addr": spec.local_addr,
    }
    port = spec.tcp_port or COMMAND_PORT
    rate_hz = spec.rate_hz or DEFAULT_OPTITRACK_HZ
    if spec.type == "OptiBridgeServer":
        bridge = OptiBridgeServer(
            spec.name,
            spec.addr,
            port,
            spec.obj_names,
            rate_hz,
            bridge_host=spec.bridge_host,
            bridge_port=spec.bridge_port,
            **natnet,
        )
        bridge.start()
        return bridge
    return OptiTrackClient(spec.name, spec.addr, port, spec.obj_names, rate_hz, **natnet)


def build_sensors(
    specs: Iterable[SensorSpec],
    make_camera: CameraMaker = opencv_camera,
    make_imu: ImuMaker = device_imu,
) -> dict[str, Sensor]:
    """The sensors of checked entries, cameras first, in the entries' order; none started yet
    but an OptiTrack bridge server (``optitrack_sensor``).

    Raises:
        SensorError: a sensor cannot be made: a bad camera index, face detection without
            scikit-image, a detector reading no camera (the ones made so far are closed).
    """
    entries = list(specs)
    sensors: dict[str, Sensor] = {}
    try:
        for spec in entries:
            if spec.is_camera:
                sensors[spec.name] = make_camera(spec)
        for spec in entries:
            if spec.is_imu:
                sensors[spec.name] = make_imu(spec)
            elif spec.is_device:
                sensors[spec.name] = device_sensor(spec)
        for spec in entries:
            if spec.is_camera or spec.is_device:
                continue
            cameras = [sensors.get(c) for c in spec.cameras]
            if not cameras or not all(isinstance(c, Camera) for c in cameras):
                raise SensorError(
                    f"sensor {spec.name!r}: cameras {list(spec.cameras)} must name cameras",
                    sensor=spec.name,
                )
            readable = [c for c in cameras if isinstance(c, Camera)]
            if spec.type == "MarkerDetector":
                sensors[spec.name] = MarkerDetector(
                    spec.name,
                    readable,
                    spec.rate_hz or DEFAULT_FREQ_HZ,
                    cards={card: list(ids) for card, ids in spec.cards.items()},
                    dictionary=spec.dictionary,
                    marker_size=spec.marker_size,
                    families=spec.families,
                )
            elif spec.type == "BlobDetector":
                sensors[spec.name] = BlobDetector(
                    spec.name,
                    readable,
                    spec.rate_hz or DEFAULT_BLOB_FREQ_HZ,
                    filters=spec.filters,
                    min_radius=spec.min_radius,
                )
            elif spec.type == "PoseSkeleton":
                if len(readable) != 1:
                    raise SensorError(
                        f"sensor {spec.name!r}: a PoseSkeleton reads one camera", sensor=spec.name
                    )
                sensors[spec.name] = PoseSkeleton(
                    spec.name, readable[0], spec.rate_hz or DEFAULT_POSE_FREQ_HZ, python=spec.python
                )
            elif spec.type == "FaceDetector":
                sensors[spec.name] = FaceDetector(
                    spec.name,
                    readable,
                    spec.rate_hz or DEFAULT_FACE_FREQ_HZ,
                    min_size=spec.min_size,
                    cascade=spec.cascade,
                )
    except BaseException:
        for sensor in sensors.values():
            sensor.close()
        raise
    return {spec.name: sensors[spec.name] for spec in entries if spec.name in sensors}
