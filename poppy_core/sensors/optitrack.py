"""``OptiTrackClient``: the rigid bodies OptiTrack's Motive tracks, read from its NatNet stream.

pypot's client (pypot 5.0.2, ``pypot.sensor.optitrack``) read Motive over VRPN; Motive streams
NatNet today, and this client speaks it (``poppy_core.sensors.natnet``: NatNet 3.0 to 4.x).
pypot's API stays: config ``{"type": "OptiTrackClient", "addr": ..., "port": ...,
"obj_names": [...]}``, ``tracked_objects`` ``{name: TrackedObject(position, quaternion,
orientation, timestamp)}`` with the position in metres, the quaternion (x, y, z, w), the
orientation (yaw, pitch, roll) in radians as pypot's ``quat2euler`` computes it, and the time
of reception; ``recent_tracked_objects`` keeps those received less than 20 ms ago.

NatNet: ``addr`` is Motive's host and ``port`` its command port (1510); frames come on the data
port (1511), multicast to a group (239.255.42.99) or, in unicast, to this client. The client
sends NAT_CONNECT to learn the NatNet version and NAT_REQUEST_MODELDEF to learn the rigid
bodies' names (again when a frame carries an id it does not know); in unicast it also sends
keep-alives from both of its sockets, and reads frames arriving on either.
"""

from __future__ import annotations

import contextlib
import datetime
import logging
import socket
import threading
from collections.abc import Callable, Iterable
from typing import Any, ClassVar, NamedTuple

import numpy as np

from poppy_core.errors import SensorError
from poppy_core.sensors import natnet
from poppy_core.sensors.base import Sensor, SensorLost

logger = logging.getLogger(__name__)

DEFAULT_OPTITRACK_HZ = 120.0
"""How often waiting NatNet messages are read (Motive streams at 120 Hz by default)."""
COMMAND_PORT = 1510
DATA_PORT = 1511
MULTICAST_GROUP = "239.255.42.99"
"""Motive's defaults (its streaming settings)."""
RECENT_S = 0.02
"""``recent_tracked_objects``: received less than this ago (pypot's 20 ms)."""
ASK_EVERY_S = 1.0
"""How often an unanswered request (connect, model definitions) and a keep-alive go out."""
MAX_DATAGRAMS_PER_READ = 256
DATAGRAM_BYTES = 65536


def quat2euler(q: Iterable[float]) -> np.ndarray:
    """(yaw, pitch, roll) in radians of a quaternion (x, y, z, w), as pypot's ``quat2euler``."""
    qx, qy, qz, qw = (float(v) for v in q)
    sqx, sqy, sqz, sqw = qx * qx, qy * qy, qz * qz, qw * qw
    invs = 1.0 / (sqx + sqy + sqz + sqw)
    yaw = np.arctan2(2.0 * (qx * qz + qy * qw) * invs, (sqx - sqy - sqz + sqw) * invs)
    pitch = -np.arcsin(np.clip(2.0 * (qx * qy - qz * qw) * invs, -1.0, 1.0))
    roll = np.arctan2(2.0 * (qy * qz + qx * qw) * invs, (-sqx + sqy - sqz + sqw) * invs)
    return np.array((yaw, pitch, roll))


class TrackedObject(NamedTuple):
    """One tracked object (pypot's namedtuple): position (m), quaternion (x, y, z, w),
    orientation (yaw, pitch, roll in radians) and the ``datetime`` it was received."""

    position: np.ndarray
    quaternion: np.ndarray
    orientation: np.ndarray
    timestamp: datetime.datetime

    def as_dict(self) -> dict[str, Any]:
        """Plain data (JSON; the timestamp in ISO 8601)."""
        return {
            "position": [float(v) for v in self.position],
            "quaternion": [float(v) for v in self.quaternion],
            "orientation": [float(v) for v in self.orientation],
            "timestamp": self.timestamp.isoformat(),
        }

    @classmethod
    def from_dict(cls, data: Any) -> TrackedObject:
        """The object of ``as_dict``'s form.

        Raises:
            ValueError: not that form.
        """
        try:
            position = np.array([float(v) for v in data["position"]])
            quaternion = np.array([float(v) for v in data["quaternion"]])
            orientation = np.array([float(v) for v in data["orientation"]])
            timestamp = datetime.datetime.fromisoformat(data["timestamp"])
        except (KeyError, TypeError, ValueError) as exc:
            raise ValueError(f"not a tracked object ({type(exc).__name__}: {exc})") from None
        shapes = (position.shape, quaternion.shape, orientation.shape)
        if shapes != ((3,), (4,), (3,)):
            raise ValueError("a tracked object needs 3 position, 4 quaternion, 3 angles")
        return cls(position, quaternion, orientation, timestamp)


def tracked(position: Iterable[float], quaternion: Iterable[float]) -> TrackedObject:
    """A tracked object received now."""
    quat = np.array([float(v) for v in quaternion])
    return TrackedObject(
        np.array([float(v) for v in position]), quat, quat2euler(quat), datetime.datetime.now()
    )


class TrackedStore:
    """The latest object of each name and when it came (shared by the NatNet and ZMQ clients)."""

    def __init__(self, clock: Callable[[], float], recent_s: float) -> None:
        self._clock = clock
        self._recent_s = recent_s
        self._lock = threading.Lock()
        self._objects: dict[str, tuple[TrackedObject, float]] = {}

    def put(self, name: str, obj: TrackedObject) -> None:
        with self._lock:
            self._objects[name] = (obj, self._clock())

    def all(self) -> dict[str, TrackedObject]:
        with self._lock:
            return {name: obj for name, (obj, _) in self._objects.items()}

    def recent(self) -> dict[str, TrackedObject]:
        now = self._clock()
        with self._lock:
            return {n: o for n, (o, at) in self._objects.items() if now - at < self._recent_s}


def _udp(local_addr: str, port: int) -> socket.socket:
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        sock.bind((local_addr, port))
        sock.setblocking(False)
    except OSError:
        sock.close()
        raise
    return sock


class OptiTrackClient(Sensor):
    """The named rigid bodies Motive at ``addr`` streams over NatNet.

    Args:
        name: the sensor's name.
        addr: Motive's host (commands go there).
        port: Motive's command port.
        obj_names: the rigid bodies to keep (Motive's names).
        rate_hz: how often waiting messages are read.
        data_port: the port frames come to.
        multicast: the group frames are multicast to; None: unicast (sent to this client).
        local_addr: the address (interface) the client binds and joins the group on.
        recent_s: the age under which an object is recent.
    """

    registers: ClassVar[tuple[str, ...]] = ("tracked_objects", "recent_tracked_objects")

    def __init__(
        self,
        name: str,
        addr: str,
        port: int = COMMAND_PORT,
        obj_names: Iterable[str] = (),
        rate_hz: float = DEFAULT_OPTITRACK_HZ,
        *,
        data_port: int = DATA_PORT,
        multicast: str | None = MULTICAST_GROUP,
        local_addr: str = "0.0.0.0",
        recent_s: float = RECENT_S,
    ) -> None:
        super().__init__(name, rate_hz)
        self.addr = addr
        self.port = port
        self.obj_names = tuple(obj_names)
        self.data_port = data_port
        self.multicast = multicast
        self.local_addr = local_addr
        self._store = TrackedStore(self.clock_s, recent_s)
        self._sockets: list[socket.socket] = []
        self._version: tuple[int, int] | None = None
        self._names: dict[int, str] | None = None
        self._names_stale = False
        self._next_connect = 0.0
        self._next_modeldef = 0.0
        self._next_keepalive = 0.0
        self.server_name = ""
        """The streaming application's name (``Motive``) once it answered."""

    @property
    def tracked_objects(self) -> dict[str, TrackedObject]:
        """The latest of each named object (``{name: TrackedObject}``, a copy); empty until
        Motive tracks one."""
        self.start()
        return self._store.all()

    @property
    def recent_tracked_objects(self) -> dict[str, TrackedObject]:
        """The objects received less than 20 ms ago (pypot's)."""
        self.start()
        return self._store.recent()

    @property
    def natnet_version(self) -> tuple[int, int] | None:
        """The NatNet (major, minor) Motive streams (None until it answered)."""
        return self._version

    @property
    def where(self) -> str:
        return f"NatNet {self.addr}:{self.port}"

    def update(self) -> bool | None:
        if not self._sockets:
            self._open()
        try:
            self._ask(self.clock_s())
            fresh = False
            for sock in self._sockets:
                for _ in range(MAX_DATAGRAMS_PER_READ):
                    try:
                        packet = sock.recv(DATAGRAM_BYTES)
                    except BlockingIOError:
                        break
                    fresh = self._take(packet) or fresh
        except OSError as exc:
            self._drop()
            raise SensorLost(f"{self.where}: {exc}") from None
        return fresh

    def _ask(self, now: float) -> None:
        """Connect, model definitions and keep-alives, each again after ``ASK_EVERY_S``."""
        command = self._sockets[0]
        server = (self.addr, self.port)
        if self._version is None and now >= self._next_connect:
            command.sendto(natnet.connect_message(), server)
            self._next_connect = now + ASK_EVERY_S
        elif self._version is not None and self._asking_names() and now >= self._next_modeldef:
            command.sendto(natnet.request(natnet.NAT_REQUEST_MODELDEF), server)
            self._next_modeldef = now + ASK_EVERY_S
        if self.multicast is None and now >= self._next_keepalive:
            for sock in self._sockets:
                sock.sendto(natnet.request(natnet.NAT_KEEPALIVE), server)
            self._next_keepalive = now + ASK_EVERY_S

    def _asking_names(self) -> bool:
        return self._names is None or self._names_stale

    def _take(self, packet: bytes) -> bool:
        """One message; True when it was a frame read with the bodies' names known."""
        try:
            message_id, payload = natnet.split(packet)
            if message_id == natnet.NAT_SERVERINFO:
                self.server_name, version = natnet.parse_server_info(payload)
                natnet.check_version(version)
                if version != self._version:
                    self._version, self._names = version, None
                return False
            if self._version is None:
                return False  # frames before the server said its version cannot be read
            if message_id == natnet.NAT_MODELDEF:
                self._names = natnet.parse_model_def(payload, self._version)
                self._names_stale = False
                return False
            if message_id != natnet.NAT_FRAMEOFDATA:
                return False
            _, bodies = natnet.parse_frame(payload, self._version)
        except ValueError as exc:
            self.bad_input(f"{self.where}: {exc}")
            return False
        names = self._names
        if names is None:
            return False
        for body in bodies:
            name = names.get(body.id)
            if name is None:
                self._names_stale = True  # a body added in Motive: ask for the names again
            elif body.valid and name in self.obj_names:
                self._store.put(name, tracked(body.position, body.quaternion))
        return True

    def _open(self) -> None:
        opened: list[socket.socket] = []
        try:
            opened.append(_udp(self.local_addr, 0))
            if self.multicast is None:
                opened.append(_udp(self.local_addr, self.data_port))
            else:
                data = _udp("", self.data_port)
                opened.append(data)
                group = socket.inet_aton(self.multicast) + socket.inet_aton(self.local_addr)
                data.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP, group)
        except OSError as exc:
            for sock in opened:
                sock.close()
            raise SensorLost(
                f"cannot listen for NatNet on {self.local_addr}:{self.data_port}: {exc}"
            ) from None
        self._sockets = opened
        self._version, self._names, self._names_stale = None, None, False
        self._next_connect = self._next_modeldef = self._next_keepalive = 0.0

    def reconnect(self) -> None:
        try:
            self._open()
        except SensorLost as exc:
            raise SensorError(str(exc), sensor=self.name) from None

    def _drop(self) -> None:
        sockets, self._sockets = self._sockets, []
        for sock in sockets:
            with contextlib.suppress(OSError):
                sock.close()

    def release(self) -> None:
        self._drop()
