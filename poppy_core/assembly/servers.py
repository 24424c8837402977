"""``serve(robot, spec) -> ServerSet``: the one place a robot's servers are built and stopped.

``poppy serve`` and the creature classes (``PoppyErgoJr(use_http=True, use_ws=True)``) both come
here. Every protocol of one set shares one ``RobotService`` (so one teleoperation registry: a
motor is teleoperated by one WebSocket connection, whichever port it came through), one Host and
Origin policy (Snap!'s adds snap.berkeley.edu), one token, and one shutdown order: Zenoh, ZMQ,
Snap!, WebSocket, HTTP (the reverse of starting), then the Zenoh session, then the service's
recordings and teleoperations (the ROS 2 node stops first). The Zenoh session
(``ServerSet.zenoh_session``) is one per set, opened before anything serves: every server on
Zenoh (the fleet node, the ROS 2 node) declares on it. Each server is built by its builder in
``server_builders``. Importing this module loads no server library; ``serve`` does.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Iterator
from typing import TYPE_CHECKING, Any, Protocol, cast

from poppy_core.assembly.serve_checks import PROTOCOLS
from poppy_core.assembly.serve_spec import ServeSpec
from poppy_core.assembly.server_builders import (
    add_foxglove,
    add_http,
    add_ros2,
    add_snap,
    add_ws,
    add_zenoh,
    add_zmq,
    fleet_page,
    name_and_announce,
    own_pages,
    ros2_session,
)
from poppy_core.schedule import close_all

if TYPE_CHECKING:
    from poppy_core.robot import Robot
    from poppy_core.server import OriginPolicy, RobotService
    from poppy_core.server.announce import Announcer
    from poppy_core.server.background import BackgroundServer
    from poppy_core.server.foxglove import FoxgloveServer
    from poppy_core.server.ros2 import Ros2Node
    from poppy_core.server.snap import SnapServer
    from poppy_core.server.zenoh import ZenohRobotServer
    from poppy_core.server.zmqserver import ZmqRobotServer

logger = logging.getLogger(__name__)


class Server(Protocol):
    """What every server of a set is, whatever its protocol (REST, WebSocket, ZMQ, Snap!,
    Zenoh, ROS 2): where it serves, whether it runs, started and stopped by its set."""

    @property
    def url(self) -> str:
        """Where clients reach it (``http://...``, ``tcp://...``, ``zenoh:NAME``...)."""
        ...

    @property
    def port(self) -> int | None:
        """Its TCP port (None on Zenoh: the session's endpoints are its addresses)."""
        ...

    @property
    def running(self) -> bool:
        """True while it serves."""
        ...

    def start(self) -> object:
        """Serve in the background."""
        ...

    def stop(self) -> None:
        """Stop serving (idempotent)."""
        ...


class ServerSet:
    """The servers of one robot, sharing ``service`` and ``policy``.

    Attributes:
        service: the one ``RobotService`` of every protocol.
        policy: the Host and Origin rules of the HTTP and WebSocket servers.
        app: the HTTP app (``None`` without ``http``).
        servers: protocol -> its ``Server``, in starting order.
    """

    def __init__(self, service: RobotService, policy: OriginPolicy, app: Any) -> None:
        self.service = service
        self.policy = policy
        self.app = app
        self.servers: dict[str, Server] = {}
        self.announcer: Announcer | None = None
        """The mDNS announcement (``announce``); ``announcer.name`` is the name won."""
        self.zenoh_session: Any = None
        """The one Zenoh session of the set (``zenoh.Session``), or None without ``zenoh``."""
        self._stopped = False

    @property
    def http(self) -> BackgroundServer | None:
        """The REST server."""
        return cast("BackgroundServer | None", self.servers.get("http"))

    @property
    def ws(self) -> BackgroundServer | None:
        """pypot's WebSocket server."""
        return cast("BackgroundServer | None", self.servers.get("ws"))

    @property
    def zmq(self) -> ZmqRobotServer | None:
        """pypot's ZMQ server."""
        return cast("ZmqRobotServer | None", self.servers.get("zmq"))

    @property
    def snap(self) -> SnapServer | None:
        """The Snap! server."""
        return cast("SnapServer | None", self.servers.get("snap"))

    @property
    def zenoh(self) -> ZenohRobotServer | None:
        """The robot on Zenoh."""
        return cast("ZenohRobotServer | None", self.servers.get("zenoh"))

    @property
    def ros2(self) -> Ros2Node | None:
        """The robot as a ROS 2 node."""
        return cast("Ros2Node | None", self.servers.get("ros2"))

    @property
    def foxglove(self) -> FoxgloveServer | None:
        """The robot for the Foxglove app."""
        return cast("FoxgloveServer | None", self.servers.get("foxglove"))

    @property
    def running(self) -> bool:
        """True while every server serves."""
        return bool(self.servers) and all(s.running for s in self.servers.values())

    def start(self) -> ServerSet:
        """Serve every server in the background (each was bound by ``serve``)."""
        for server in self.servers.values():
            server.start()
        return self

    def stop(self) -> None:
        """Stop the servers (Zenoh, ZMQ, Snap!, WebSocket, HTTP), the Zenoh session, then the
        service, saving its takes (again: nothing). Every part is stopped whatever fails first:
        each failure is logged once at WARNING."""
        if self._stopped:
            return
        self._stopped = True
        close_all(self._stopping_steps(), logger, "the servers")

    def _stopping_steps(self) -> Iterator[tuple[str, Callable[[], object]]]:
        if self.announcer is not None:  # goodbye first: nobody is sent to a server that is going
            yield "the mDNS announcement", self.announcer.stop
        for name in reversed(PROTOCOLS):
            if name in self.servers:
                yield f"the {name} server", self.servers[name].stop
        if self.zenoh_session is not None:
            yield "the Zenoh session", self._close_session
        yield "the recordings and playbacks", self.service.close

    def _close_session(self) -> None:
        session, self.zenoh_session = self.zenoh_session, None
        session.close()

    def __enter__(self) -> ServerSet:
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()


def serve(robot: Robot, spec: ServeSpec, *, start: bool = True) -> ServerSet:
    """Build (and bind) the servers ``spec`` asks for over ``robot``; serve them unless ``start``
    is False (each then serves on ``server.start()`` or pypot's ``server.run()``).

    Every port is bound before any server serves, so a busy port is an error before anything
    runs; when a step fails, whatever was bound or started is stopped.

    Raises:
        ListenError: a port is taken or an address unusable.
        RuntimeError: a server did not start (its log says why).
        ConfigError: a Zenoh endpoint or configuration that cannot be used.
        MissingExtraError: the ``server`` (or ``zmq``, ``appliance``, ``fleet``, ``ros2``,
            ``foxglove``) extra is missing.
        ArgumentError: ``foxglove`` off loopback while a token is required.
    """
    from poppy_core.server import RobotService, create_app

    listens = spec.listens()
    policy = spec.policy()
    service = RobotService(robot)
    app = None
    if "http" in listens or spec.zenoh is not None:
        app = create_app(
            robot, service=service, token=spec.token, policy=policy, stream_rate_hz=spec.ws_rate_hz
        )
    servers = ServerSet(service, policy, app if "http" in listens else None)
    try:
        if "http" in listens:
            add_http(servers, spec, listens["http"], app)
        if "ws" in listens:
            add_ws(servers, spec, listens["ws"])
        if "zmq" in listens:
            add_zmq(servers, robot, listens["zmq"])
        if "snap" in listens:
            add_snap(servers, robot, spec, listens["snap"])
        if spec.ros2 is not None:  # first: its session stamps samples, for both nodes
            ros2_session(servers, spec, spec.ros2)
        if spec.zenoh is not None:
            add_zenoh(servers, spec, spec.zenoh, app)
        if spec.ros2 is not None:
            add_ros2(servers, spec, spec.ros2)
        if "foxglove" in listens:
            add_foxglove(servers, spec, listens["foxglove"])
        own_pages(servers)
        name_and_announce(servers, robot, spec)
        fleet_page(servers)
        if start:
            servers.start()
    except BaseException:
        servers.stop()
        raise
    return servers
