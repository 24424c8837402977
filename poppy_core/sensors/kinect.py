"""``KinectSensor``: the skeletons a Kinect tracks, from the Kinect skeleton server over ZMQ.

pypot's client (pypot 5.0.2, ``pypot.sensor.kinect.sensor``; the server, Windows only, runs
Microsoft's Kinect SDK): config ``{"type": "KinectSensor", "addr": "193.50.110.177", "port":
9999}``. The wire, as facts: a ZMQ SUB socket connected to ``tcp://addr:port``, subscribed to
everything; each skeleton is a JSON message ``{"shape": [20, 10], "timestamp": ...,
"user_index": ...}`` followed by a message of ``shape[0] * shape[1]`` comma-separated numbers:
per joint (in ``JOINTS``' order) a homogeneous position x, y, z, w (metres once divided by w),
the pixel coordinate x, y in the depth image, and the orientation quaternion x, y, z, w.
``tracked_skeleton`` is ``{user_index: Skeleton}``, the latest skeleton of each user.
"""

from __future__ import annotations

import contextlib
import json
import logging
import threading
from collections import namedtuple
from collections.abc import Callable, Iterable
from typing import Any, ClassVar, NamedTuple

import numpy as np

from poppy_core.errors import MissingExtraError, SensorError
from poppy_core.extras import require
from poppy_core.sensors.base import Sensor, SensorLost

logger = logging.getLogger(__name__)

DEFAULT_KINECT_HZ = 30.0
"""How often waiting messages are read (the Kinect tracks at 30 frames a second)."""
MAX_MESSAGES_PER_READ = 64

TORSO = ("hip_center", "spine", "shoulder_center", "head")
LEFT_ARM = ("shoulder_left", "elbow_left", "wrist_left", "hand_left")
RIGHT_ARM = ("shoulder_right", "elbow_right", "wrist_right", "hand_right")
LEFT_LEG = ("hip_left", "knee_left", "ankle_left", "foot_left")
RIGHT_LEG = ("hip_right", "knee_right", "ankle_right", "foot_right")
JOINTS = TORSO + LEFT_ARM + RIGHT_ARM + LEFT_LEG + RIGHT_LEG
"""The Kinect SDK's 20 skeleton joints, in the server's order (pypot's names)."""
VALUES_PER_JOINT = 10

Point2D = namedtuple("Point2D", ("x", "y"))
Point3D = namedtuple("Point3D", ("x", "y", "z"))
Quaternion = namedtuple("Quaternion", ("x", "y", "z", "w"))
"""pypot's ``pypot.utils`` tuples (field names and order)."""


class SkeletonJoint(namedtuple("Joint", ("position", "orientation", "pixel_coordinate"))):
    """One joint: ``position`` (Point3D, m), ``orientation`` (Quaternion), ``pixel_coordinate``."""

    def as_dict(self) -> dict[str, Any]:
        """Plain data (JSON)."""
        return {
            "position": list(self.position),
            "orientation": list(self.orientation),
            "pixel_coordinate": list(self.pixel_coordinate),
        }


class Skeleton(NamedTuple):
    """One user's skeleton: ``timestamp``, ``user_id`` and a joint per name of ``joints``."""

    timestamp: Any
    user_id: Any
    hip_center: SkeletonJoint
    spine: SkeletonJoint
    shoulder_center: SkeletonJoint
    head: SkeletonJoint
    shoulder_left: SkeletonJoint
    elbow_left: SkeletonJoint
    wrist_left: SkeletonJoint
    hand_left: SkeletonJoint
    shoulder_right: SkeletonJoint
    elbow_right: SkeletonJoint
    wrist_right: SkeletonJoint
    hand_right: SkeletonJoint
    hip_left: SkeletonJoint
    knee_left: SkeletonJoint
    ankle_left: SkeletonJoint
    foot_left: SkeletonJoint
    hip_right: SkeletonJoint
    knee_right: SkeletonJoint
    ankle_right: SkeletonJoint
    foot_right: SkeletonJoint

    @property
    def joints(self) -> tuple[str, ...]:
        """The joints' names (pypot's ``Skeleton.joints``)."""
        return JOINTS

    def as_dict(self) -> dict[str, Any]:
        """Plain data (JSON): the timestamp, the user and each joint by name."""
        return {
            "timestamp": self.timestamp,
            "user_id": self.user_id,
            "joints": {name: getattr(self, name).as_dict() for name in JOINTS},
        }


def parse_skeleton(header: bytes, values: bytes) -> Skeleton:
    """The skeleton of one header message and its values message.

    Raises:
        ValueError: not the server's form (the message says what).
    """
    try:
        meta = json.loads(header)
        shape = [int(v) for v in meta["shape"]]
        timestamp, user = meta["timestamp"], meta["user_index"]
    except (ValueError, TypeError, KeyError) as exc:
        raise ValueError(f"not a skeleton header ({exc})") from None
    if shape != [len(JOINTS), VALUES_PER_JOINT]:
        raise ValueError(f"a skeleton of shape {shape}, not [{len(JOINTS)}, {VALUES_PER_JOINT}]")
    try:
        array = np.array([float(v) for v in values.split(b",")], dtype=float)
        array = array.reshape(shape)
    except ValueError:
        raise ValueError(f"not {shape[0]}×{shape[1]} comma-separated numbers") from None
    if not np.isfinite(array).all():
        raise ValueError("a skeleton with NaN or infinite values")
    joints = []
    for row in array:
        x, y, z, w = (float(v) for v in row[:4])
        if w == 0:
            raise ValueError("a joint position with w = 0")
        joints.append(
            SkeletonJoint(
                Point3D(x / w, y / w, z / w),
                Quaternion(*(float(v) for v in row[6:10])),
                Point2D(float(row[4]), float(row[5])),
            )
        )
    return Skeleton(timestamp, user, *joints)


def skeleton_sensors(sensors: Iterable[Sensor]) -> list[Sensor]:
    """The sensors that give skeletons (``tracked_skeleton``): Kinects and camera poses."""
    return [s for s in sensors if "tracked_skeleton" in s.registers]


SocketOpener = Callable[[str, int], Any]
"""Opens the SUB socket: (addr, port) -> a pyzmq socket subscribed to everything."""


def open_subscriber(addr: str, port: int) -> Any:
    """A ZMQ SUB socket connected to ``tcp://addr:port``, subscribed to everything."""
    require("zmq", extra="zmq", feature="the Kinect sensor")
    import zmq

    socket: Any = zmq.Context.instance().socket(zmq.SUB)
    socket.setsockopt(zmq.LINGER, 0)
    socket.setsockopt(zmq.SUBSCRIBE, b"")
    socket.connect(f"tcp://{addr}:{port}")
    return socket


class KinectSensor(Sensor):
    """The skeletons the Kinect skeleton server at ``addr:port`` publishes (pypot's).

    Args:
        name: the sensor's name.
        addr: the server's host.
        port: its ZMQ port.
        rate_hz: how often waiting messages are read.
        opener: opens the socket (tests).
    """

    registers: ClassVar[tuple[str, ...]] = ("tracked_skeleton",)

    def __init__(
        self,
        name: str,
        addr: str,
        port: int,
        rate_hz: float = DEFAULT_KINECT_HZ,
        *,
        opener: SocketOpener = open_subscriber,
    ) -> None:
        super().__init__(name, rate_hz)
        self.addr = addr
        self.port = port
        self._opener = opener
        self._socket: Any = None
        self._header: bytes | None = None
        self._skeletons: dict[Any, Skeleton] = {}
        self._skeletons_lock = threading.Lock()
        if opener is open_subscriber:
            try:
                require("zmq", extra="zmq", feature="the Kinect sensor")
            except MissingExtraError as exc:  # the robot builds; health says why
                logger.warning("%s %s is not available: %s", self.kind, name, exc)
                self.fail(str(exc))

    @property
    def tracked_skeleton(self) -> dict[Any, Skeleton]:
        """The latest skeleton of each user (``{user_index: Skeleton}``, a copy); empty until
        the server sends one."""
        self.start()
        with self._skeletons_lock:
            return dict(self._skeletons)

    @tracked_skeleton.setter
    def tracked_skeleton(self, skeleton: Skeleton) -> None:
        with self._skeletons_lock:
            self._skeletons[skeleton.user_id] = skeleton

    def remove_user(self, user_index: Any) -> None:
        """Forget a user's skeleton (pypot's)."""
        with self._skeletons_lock:
            self._skeletons.pop(user_index, None)

    def remove_all_users(self) -> None:
        """Forget every skeleton (pypot's)."""
        with self._skeletons_lock:
            self._skeletons.clear()

    def update(self) -> bool | None:
        if self._socket is None:
            self._open()
        import zmq

        fresh = False
        try:
            for _ in range(MAX_MESSAGES_PER_READ):
                try:
                    message = self._socket.recv(zmq.NOBLOCK)
                except zmq.Again:
                    break
                fresh = self._take(message) or fresh
        except zmq.ZMQError as exc:
            self._drop()
            raise SensorLost(f"tcp://{self.addr}:{self.port}: {exc}") from None
        return fresh

    def _take(self, message: bytes) -> bool:
        """A header is kept for the values that follow it; True when a skeleton was read."""
        if self._header is None:
            self._header = message
            return False
        header, self._header = self._header, None
        try:
            skeleton = parse_skeleton(header, message)
        except ValueError as exc:
            self.bad_input(f"tcp://{self.addr}:{self.port}: {exc}")
            if message.lstrip().startswith(b"{"):
                self._header = message  # out of step: this one is the next header
            return False
        self.tracked_skeleton = skeleton
        return True

    def _open(self) -> None:
        try:
            self._socket = self._opener(self.addr, self.port)
        except OSError as exc:
            raise SensorLost(f"cannot connect to tcp://{self.addr}:{self.port}: {exc}") from None
        self._header = None

    def reconnect(self) -> None:
        try:
            self._open()
        except SensorLost as exc:
            raise SensorError(str(exc), sensor=self.name) from None

    def _drop(self) -> None:
        socket, self._socket = self._socket, None
        if socket is not None:
            with contextlib.suppress(Exception):
                socket.close()

    def release(self) -> None:
        self._drop()
