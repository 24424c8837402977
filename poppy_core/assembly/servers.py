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
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol, cast

from poppy_core.assembly.serve_checks import (
    check_foxglove,
    check_origins,
    check_ports,
    exposure,
)
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
from poppy_core.checks import robot_name
from poppy_core.ros2_wire import Ros2Settings
from poppy_core.schedule import close_all
from poppy_core.zenoh_wire import ZenohSettings

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

PROTOCOLS = ("http", "ws", "zmq", "snap", "zenoh", "ros2", "foxglove")
"""pypot's attribute names of the servers (``robot.http``...), ``zenoh``, ``ros2`` and
``foxglove``, in the order they start."""
DEFAULT_PORTS = {"http": 8080, "ws": 9009, "zmq": 6768, "snap": 6969}
"""pypot's default ports (``zmq``: the documentation's ZMQ example)."""
LOOPBACK = "127.0.0.1"

logger = logging.getLogger(__name__)


@dataclass(frozen=True)
class Listen:
    """Where one server listens (``port`` 0 picks a free one)."""

    host: str = LOOPBACK
    port: int = 0


@dataclass(frozen=True)
class ServeSpec:
    """Which servers to build for a robot, and the rules they share.

    Attributes:
        http: the REST API and page (with the stream at ``/api/v1/ws``), or None.
        ws: pypot's WebSocket port (the state stream at ``/``), or None.
        zmq: pypot's ZMQ request/reply server, or None.
        snap: the Snap! server, or None.
        token: required on every route and WebSocket (not ZMQ, which has none).
        cors: browser origins allowed besides the servers' own pages (``"*"``: any).
        allow_hosts: Host names answered besides loopback names, IPs and the listening host.
        ws_rate_hz: the state stream's default rate.
        snap_dir: a downloaded Snap! served at ``/app/`` on the Snap! port.
        name: the robot's name (``checks.robot_name``: one DNS label, kept lower case; a bad
            one is an ArgumentError here): ``NAME`` and ``NAME.local`` are accepted as Host
            names, and the pages the robot serves under them on any port count as its own; on
            Zenoh the robot is ``poppy/NAME`` (the host's name when None).
        announce: announce ``NAME.local`` (default ``poppy``) and the robot's services over
            mDNS/DNS-SD on the interfaces the servers listen on (``appliance`` extra).
        http_alias_ports: more ports serving the REST API and page, on ``http``'s host (the
            appliance serves port 80 and keeps 8080); their pages count as the server's own.
        report: called with one line the first time an origin or Host name is refused.
        zenoh: the robot on Zenoh under ``poppy/<name>`` (``ZenohSettings``: endpoints,
            configuration file, scouting), or None.
        state_rate_hz: the Zenoh state messages per second (the sync loop's rate).
        ros2: the robot as a ROS 2 node on rmw_zenoh's wire (``Ros2Settings``: domain,
            namespace, node; its Zenoh settings serve when ``zenoh`` is None), or None.
        foxglove: foxglove-sdk's WebSocket server for the Foxglove app (read only; it has no
            authentication: with a token it serves on loopback only), or None.
        settings_file: the appliance's serve options file (``poppy serve --settings``): the
            page's settings switch Snap! and ZMQ there.
        token_file: the file ``token`` was read from (``--token-file``): the page's settings
            change the token there.
        warn: called with each exposure warning when the spec is made (a server on another
            address than loopback without a token, ZMQ off loopback, ``cors`` ``"*"``);
            default: a WARNING of this module's logger.

    A spec checks itself when it is made (``serve_checks``): a port that clashes, a name, an
    origin or a Host name that is not one is an ``ArgumentError`` (a ``ValueError``) whose
    ``field`` names the attribute; then the exposure warnings are given to ``warn``.
    """

    http: Listen | None = None
    ws: Listen | None = None
    zmq: Listen | None = None
    snap: Listen | None = None
    token: str | None = None
    cors: tuple[str, ...] = ()
    allow_hosts: tuple[str, ...] = ()
    ws_rate_hz: float = 30.0
    snap_dir: Path | None = None
    name: str | None = None
    announce: bool = False
    http_alias_ports: tuple[int, ...] = ()
    report: Callable[[str], None] | None = field(default=None, compare=False)
    zenoh: ZenohSettings | None = None
    state_rate_hz: float = 50.0
    ros2: Ros2Settings | None = None
    foxglove: Listen | None = None
    settings_file: Path | None = None
    token_file: Path | None = None
    warn: Callable[[str], None] | None = field(default=None, compare=False)

    def __post_init__(self) -> None:
        """Check the spec: ``name`` as the robot's one name on mDNS and Zenoh
        (``checks.robot_name``: ``Poppy.local`` -> ``poppy``), the ports, the origins and Host
        names (ArgumentError, a ValueError); then warn of what it exposes."""
        if self.name is not None:
            object.__setattr__(self, "name", robot_name(self.name, "name"))
        check_ports(self)
        check_foxglove(self)
        check_origins(self)
        for line in exposure(self):
            (self.warn or logger.warning)(line)

    def policy(self) -> OriginPolicy:
        """The Host and Origin rules of the HTTP and WebSocket servers, made from the spec (a
        new one each call: a server set adds its own ports and names to it)."""
        from poppy_core.server import OriginPolicy

        return OriginPolicy.for_server(
            self.host,
            cors=self.cors,
            allow_hosts=self.allow_hosts,
            name=self.name,
            report=self.report,
        )

    def snap_policy(self, host: str) -> OriginPolicy:
        """The Snap! server's rules on ``host``: the REST server's, snap.berkeley.edu allowed,
        the robot's name its own."""
        from poppy_core.server.snap.server import snap_policy

        policy = snap_policy(host, cors=self.cors, allow_hosts=self.allow_hosts, report=self.report)
        if self.name is not None:
            policy.with_names([self.name])  # Snap! projects call http://poppy.local:6969 too
        return policy

    def listens(self) -> dict[str, Listen]:
        """Protocol -> where it listens, for the servers asked for, in starting order."""
        wanted = {
            "http": self.http,
            "ws": self.ws,
            "zmq": self.zmq,
            "snap": self.snap,
            "foxglove": self.foxglove,
        }
        return {name: where for name, where in wanted.items() if where is not None}

    @property
    def host(self) -> str:
        """The address the policy is made for: the first server's (loopback when none)."""
        listens = list(self.listens().values())
        return listens[0].host if listens else LOOPBACK


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
