"""The OptiTrack bridge: Motive's tracked objects passed on over ZMQ to another machine.

pypot's (pypot 5.0.2, ``pypot.sensor.optibridge``): ``OptiBridgeServer`` tracks objects and
publishes ``recent_tracked_objects`` on a ZMQ PUB socket bound at ``bridge_host:bridge_port``
every 20 ms; its client (pypot's ``optibridge.OptiTrackClient``, poppy's ``OptiBridgeClient``)
subscribes at ``addr:port`` and keeps, from each message, the objects it names.

pypot's messages are pickles. Unpickling what comes from the network runs whatever code the
sender chose, so poppy sends and reads JSON instead: ``{name: {"position": [x, y, z],
"quaternion": [x, y, z, w], "orientation": [yaw, pitch, roll], "timestamp": ISO 8601}}``. A
pickled message (a pypot server) is refused, counted and said once; run poppy's server.
"""

from __future__ import annotations

import contextlib
import json
import logging
from collections.abc import Callable, Iterable
from typing import Any, ClassVar

from poppy_core.errors import MissingExtraError, SensorError
from poppy_core.extras import require
from poppy_core.sensors.base import Sensor, SensorLost
from poppy_core.sensors.optitrack import (
    COMMAND_PORT,
    DEFAULT_OPTITRACK_HZ,
    OptiTrackClient,
    TrackedObject,
)

logger = logging.getLogger(__name__)

PUBLISH_EVERY_S = 0.02
"""pypot's server sends every 20 ms."""
DEFAULT_BRIDGE_HZ = 100.0
"""How often the bridge client reads waiting messages."""
MAX_MESSAGES_PER_READ = 64
PICKLE_PROTOCOL_2_UP = b"\x80"
"""How a pickle of protocol 2 or later (pypot's under Python 3) begins."""

Opener = Callable[[str, int], Any]
"""Opens a ZMQ socket: (host, port) -> a pyzmq socket."""


def open_publisher(host: str, port: int) -> Any:
    """A ZMQ PUB socket bound at ``tcp://host:port``."""
    require("zmq", extra="zmq", feature="the OptiTrack bridge")
    import zmq

    sock: Any = zmq.Context.instance().socket(zmq.PUB)
    sock.setsockopt(zmq.LINGER, 0)
    sock.bind(f"tcp://{host}:{port}")
    return sock


def open_subscriber(host: str, port: int) -> Any:
    """A ZMQ SUB socket connected to ``tcp://host:port``, subscribed to everything."""
    require("zmq", extra="zmq", feature="the OptiTrack bridge")
    import zmq

    sock: Any = zmq.Context.instance().socket(zmq.SUB)
    sock.setsockopt(zmq.LINGER, 0)
    sock.setsockopt(zmq.SUBSCRIBE, b"")
    sock.connect(f"tcp://{host}:{port}")
    return sock


def encode(objects: dict[str, TrackedObject]) -> bytes:
    """The bridge's JSON message of some tracked objects."""
    return json.dumps({name: obj.as_dict() for name, obj in objects.items()}).encode()


def decode(message: bytes) -> dict[str, TrackedObject]:
    """The tracked objects of a bridge message.

    Raises:
        ValueError: not the bridge's JSON (a pickle is refused, the message says why).
    """
    if message.startswith(PICKLE_PROTOCOL_2_UP):
        raise ValueError(
            "a pickled message (pypot's bridge server): refused, unpickling network data can "
            "run code; run poppy's OptiBridgeServer, which sends JSON"
        )
    try:
        data = json.loads(message)
    except ValueError:
        raise ValueError("not a JSON message of tracked objects") from None
    if not isinstance(data, dict):
        raise ValueError("not a JSON object of tracked objects")
    return {str(name): TrackedObject.from_dict(value) for name, value in data.items()}


def _zmq_available(sensor: Sensor) -> None:
    try:
        require("zmq", extra="zmq", feature="the OptiTrack bridge")
    except MissingExtraError as exc:  # the robot builds; health says why
        logger.warning("%s %s is not available: %s", sensor.kind, sensor.name, exc)
        sensor.fail(str(exc))


class OptiBridgeServer(OptiTrackClient):
    """An ``OptiTrackClient`` that also publishes its recent objects every 20 ms over ZMQ.

    Args:
        name, addr, port, obj_names, rate_hz: as ``OptiTrackClient`` (the NatNet side).
        bridge_host: the address the PUB socket binds.
        bridge_port: its TCP port.
        opener: opens the PUB socket (tests).
        **natnet: ``OptiTrackClient``'s keyword arguments.
    """

    def __init__(
        self,
        name: str,
        addr: str,
        port: int = COMMAND_PORT,
        obj_names: Iterable[str] = (),
        rate_hz: float = DEFAULT_OPTITRACK_HZ,
        *,
        bridge_host: str,
        bridge_port: int,
        opener: Opener = open_publisher,
        **natnet: Any,
    ) -> None:
        super().__init__(name, addr, port, obj_names, rate_hz, **natnet)
        self.bridge_host = bridge_host
        self.bridge_port = bridge_port
        self._opener = opener
        self._publisher: Any = None
        self._next_publish = 0.0
        self.published = 0
        """Messages sent so far."""
        if opener is open_publisher:
            _zmq_available(self)

    def _publish_on(self) -> str:
        return f"tcp://{self.bridge_host}:{self.bridge_port}"

    def update(self) -> bool | None:
        if self._publisher is None:
            try:
                self._publisher = self._opener(self.bridge_host, self.bridge_port)
            except Exception as exc:  # a taken port: said in health, retried with backoff
                raise SensorLost(f"cannot publish on {self._publish_on()}: {exc}") from None
        fresh = super().update()
        now = self.clock_s()
        if now >= self._next_publish:
            self._publisher.send(encode(self._store.recent()))
            self.published += 1
            self._next_publish = max(self._next_publish + PUBLISH_EVERY_S, now)
        return fresh

    def reconnect(self) -> None:
        if self._publisher is None:
            try:
                self._publisher = self._opener(self.bridge_host, self.bridge_port)
            except Exception as exc:
                raise SensorError(
                    f"cannot publish on {self._publish_on()}: {exc}", sensor=self.name
                ) from None
        super().reconnect()

    def release(self) -> None:
        super().release()
        publisher, self._publisher = self._publisher, None
        if publisher is not None:
            with contextlib.suppress(Exception):
                publisher.close()


class OptiBridgeClient(Sensor):
    """The objects an ``OptiBridgeServer`` at ``addr:port`` publishes, the named ones kept.

    Args:
        name: the sensor's name.
        addr: the bridge server's host.
        port: its TCP port.
        obj_names: the objects to keep.
        rate_hz: how often waiting messages are read.
        opener: opens the SUB socket (tests).
    """

    registers: ClassVar[tuple[str, ...]] = ("tracked_objects", "recent_tracked_objects")

    def __init__(
        self,
        name: str,
        addr: str,
        port: int,
        obj_names: Iterable[str] = (),
        rate_hz: float = DEFAULT_BRIDGE_HZ,
        *,
        opener: Opener = open_subscriber,
    ) -> None:
        super().__init__(name, rate_hz)
        self.addr = addr
        self.port = port
        self.obj_names = tuple(obj_names)
        self._opener = opener
        self._socket: Any = None
        self._objects: dict[str, TrackedObject] = {}
        if opener is open_subscriber:
            _zmq_available(self)

    @property
    def tracked_objects(self) -> dict[str, TrackedObject]:
        """The named objects of the latest message (pypot's: replaced by each message)."""
        self.start()
        return dict(self._objects)

    @property
    def recent_tracked_objects(self) -> dict[str, TrackedObject]:
        """The same: the server sends only objects tracked less than 20 ms ago (pypot's)."""
        return self.tracked_objects

    def update(self) -> bool | None:
        if self._socket is None:
            try:
                self._socket = self._opener(self.addr, self.port)
            except OSError as exc:
                where = f"tcp://{self.addr}:{self.port}"
                raise SensorLost(f"cannot connect to {where}: {exc}") from None
        import zmq

        fresh = False
        try:
            for _ in range(MAX_MESSAGES_PER_READ):
                try:
                    message = self._socket.recv(zmq.NOBLOCK)
                except zmq.Again:
                    break
                try:
                    objects = decode(message)
                except ValueError as exc:
                    self.bad_input(f"tcp://{self.addr}:{self.port}: {exc}")
                    continue
                self._objects = {k: v for k, v in objects.items() if k in self.obj_names}
                fresh = True
        except zmq.ZMQError as exc:
            self._drop()
            raise SensorLost(f"tcp://{self.addr}:{self.port}: {exc}") from None
        return fresh

    def reconnect(self) -> None:
        try:
            self._socket = self._opener(self.addr, self.port)
        except Exception as exc:
            raise SensorError(
                f"cannot connect to tcp://{self.addr}:{self.port}: {exc}", sensor=self.name
            ) from None

    def _drop(self) -> None:
        sock, self._socket = self._socket, None
        if sock is not None:
            with contextlib.suppress(Exception):
                sock.close()

    def release(self) -> None:
        self._drop()
