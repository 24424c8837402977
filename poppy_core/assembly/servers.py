"""``serve(robot, spec) -> ServerSet``: the one place a robot's servers are built and stopped.

``poppy serve`` and the creature classes (``PoppyErgoJr(use_http=True, use_ws=True)``) both come
here. Every protocol of one set shares one ``RobotService`` (so one teleoperation registry: a
motor is teleoperated by one WebSocket connection, whichever port it came through), one Host and
Origin policy (Snap!'s adds snap.berkeley.edu), one token, and one shutdown order: Zenoh, ZMQ,
Snap!, WebSocket, HTTP (the reverse of starting), then the Zenoh session, then the service's
recordings and teleoperations (the ROS 2 node stops first). The Zenoh session
(``ServerSet.zenoh_session``) is one per set, opened before anything serves: every server on
Zenoh (the fleet node, the ROS 2 node) declares on it.
Importing this module loads no server library; ``serve`` does.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from poppy_core.checks import robot_name
from poppy_core.ros2_wire import Ros2Settings
from poppy_core.zenoh_wire import ZenohSettings

if TYPE_CHECKING:
    from poppy_core.robot import Robot
    from poppy_core.server import OriginPolicy, RobotService
    from poppy_core.server.announce import Announcer
    from poppy_core.server.background import BackgroundServer
    from poppy_core.server.ros2 import Ros2Node
    from poppy_core.server.snap import SnapServer
    from poppy_core.server.zenoh import ZenohRobotServer
    from poppy_core.server.zmqserver import ZmqRobotServer

PROTOCOLS = ("http", "ws", "zmq", "snap", "zenoh", "ros2")
"""pypot's attribute names of the servers (``robot.http``...), ``zenoh`` and ``ros2``, in the
order they start."""
SNAP_ONLINE_NOTE = (
    "Snap! opens online (snap.berkeley.edu): run `poppy snap download` once on the robot "
    "to serve Snap! offline"
)
"""The page's line when no Snap! copy is served at /app/."""
DEFAULT_PORTS = {"http": 8080, "ws": 9009, "zmq": 6768, "snap": 6969}
"""pypot's default ports (``zmq``: the documentation's ZMQ example)."""
LOOPBACK = "127.0.0.1"


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
        settings_file: the appliance's serve options file (``poppy serve --settings``): the
            page's settings switch Snap! and ZMQ there.
        token_file: the file ``token`` was read from (``--token-file``): the page's settings
            change the token there.
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
    settings_file: Path | None = None
    token_file: Path | None = None

    def __post_init__(self) -> None:
        """``name`` as the robot's one name on mDNS and Zenoh (``checks.robot_name``:
        ``Poppy.local`` -> ``poppy``; ArgumentError, a ValueError, for another name)."""
        if self.name is not None:
            object.__setattr__(self, "name", robot_name(self.name, "name"))

    def listens(self) -> dict[str, Listen]:
        """Protocol -> where it listens, for the servers asked for, in starting order."""
        wanted = {"http": self.http, "ws": self.ws, "zmq": self.zmq, "snap": self.snap}
        return {name: where for name, where in wanted.items() if where is not None}

    @property
    def host(self) -> str:
        """The address the policy is made for: the first server's (loopback when none)."""
        listens = list(self.listens().values())
        return listens[0].host if listens else LOOPBACK


class ServerSet:
    """The servers of one robot, sharing ``service`` and ``policy``.

    Attributes:
        service: the one ``RobotService`` of every protocol.
        policy: the Host and Origin rules of the HTTP and WebSocket servers.
        app: the HTTP app (``None`` without ``http``).
        servers: protocol -> its server (each has ``url``, ``port``, ``run()``, ``stop()``).
    """

    def __init__(self, service: RobotService, policy: OriginPolicy, app: Any) -> None:
        self.service = service
        self.policy = policy
        self.app = app
        self.servers: dict[str, Any] = {}
        self.announcer: Announcer | None = None
        """The mDNS announcement (``announce``); ``announcer.name`` is the name won."""
        self.zenoh_session: Any = None
        """The one Zenoh session of the set (``zenoh.Session``), or None without ``zenoh``."""
        self._stopped = False

    @property
    def http(self) -> BackgroundServer | None:
        """The REST server."""
        return self.servers.get("http")

    @property
    def ws(self) -> BackgroundServer | None:
        """pypot's WebSocket server."""
        return self.servers.get("ws")

    @property
    def zmq(self) -> ZmqRobotServer | None:
        """pypot's ZMQ server."""
        return self.servers.get("zmq")

    @property
    def snap(self) -> SnapServer | None:
        """The Snap! server."""
        return self.servers.get("snap")

    @property
    def zenoh(self) -> ZenohRobotServer | None:
        """The robot on Zenoh."""
        return self.servers.get("zenoh")

    @property
    def ros2(self) -> Ros2Node | None:
        """The robot as a ROS 2 node."""
        return self.servers.get("ros2")

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
        service (again: nothing)."""
        if self._stopped:
            return
        self._stopped = True
        if self.announcer is not None:
            self.announcer.stop()  # goodbye first: nobody is sent to a server that is going
        for name in reversed(PROTOCOLS):
            if name in self.servers:
                self.servers[name].stop()
        if self.zenoh_session is not None:
            self.zenoh_session.close()
            self.zenoh_session = None
        self.service.close()

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
        ValueError: an origin in ``cors`` or a name in ``allow_hosts`` that is not one.
        ConfigError: a Zenoh endpoint or configuration that cannot be used.
        MissingExtraError: the ``server`` (or ``zmq``, ``appliance``, ``fleet``, ``ros2``) extra
            is missing.
    """
    from poppy_core.server import OriginPolicy, RobotService, ServerThread, create_app
    from poppy_core.server.background import BackgroundServer
    from poppy_core.server.stream import create_stream_app

    listens = spec.listens()
    policy = OriginPolicy.for_server(
        spec.host,
        cors=spec.cors,
        allow_hosts=spec.allow_hosts,
        name=spec.name,
        report=spec.report,
    )
    service = RobotService(robot)
    app = None
    if "http" in listens or spec.zenoh is not None:
        app = create_app(
            robot, service=service, token=spec.token, policy=policy, stream_rate_hz=spec.ws_rate_hz
        )
    servers = ServerSet(service, policy, app if "http" in listens else None)
    try:
        if "http" in listens:
            where = listens["http"]
            thread = ServerThread(
                app, where.host, where.port, alias_ports=spec.http_alias_ports
            ).bind()
            servers.servers["http"] = BackgroundServer("http", thread, service=service)
        if "ws" in listens:
            where = listens["ws"]
            stream = create_stream_app(service, spec.ws_rate_hz, spec.token, policy)
            thread = ServerThread(stream, where.host, where.port).bind()
            servers.servers["ws"] = BackgroundServer("ws", thread, service=service)
        if "zmq" in listens:
            from poppy_core.server.zmqserver import ZmqRobotServer

            where = listens["zmq"]
            servers.servers["zmq"] = ZmqRobotServer(robot, where.host, where.port, service=service)
        if "snap" in listens:
            _add_snap(servers, robot, spec, listens["snap"])
        if spec.ros2 is not None:  # first: its session stamps samples, for both nodes
            _ros2_session(servers, spec, spec.ros2)
        if spec.zenoh is not None:
            _add_zenoh(servers, spec, spec.zenoh, app)
        if spec.ros2 is not None:
            _add_ros2(servers, spec, spec.ros2)
        _own_pages(servers)
        _named(servers, robot, spec)
        _fleet_page(servers)
        if start:
            servers.start()
    except BaseException:
        servers.stop()
        raise
    return servers


def _named(servers: ServerSet, robot: Robot, spec: ServeSpec) -> None:
    """Give the page's settings the robot's name; announce it when asked (before serving, so
    the name won is accepted by the Host check from the first request)."""
    from poppy_core.server.settings import ServedRobot

    name = spec.name or ("poppy" if spec.announce else None)
    policies = [servers.policy] + ([servers.snap.policy] if servers.snap is not None else [])
    served = ServedRobot(
        name=name,
        protocols=tuple(servers.servers),
        token_required=bool(spec.token),
        policies=policies,
        settings_file=spec.settings_file,
        token_file=spec.token_file,
    )
    if servers.app is not None:
        servers.app.state.settings.served = served
    if not spec.announce or name is None:
        return
    from poppy_core.server.announce import Announcer

    ports = {p: s.port for p, s in servers.servers.items()}
    properties = {"creature": _creature(robot), "version": served.version}
    if spec.token:
        properties["token"] = "1"
    announcer = Announcer(
        name,
        ports,
        listen_host=spec.host,
        properties=properties,
        on_name=served.named,
    )
    servers.announcer = announcer
    served.announcer = announcer
    announcer.start()


def _creature(robot: Robot) -> str:
    profile = robot.config.profile if robot.config is not None else None
    return (profile.kind or profile.name) if profile is not None else "custom"


def _add_snap(servers: ServerSet, robot: Robot, spec: ServeSpec, where: Listen) -> None:
    from poppy_core.server.snap import create_snap_server
    from poppy_core.server.snap.server import snap_policy

    policy = snap_policy(
        where.host, cors=spec.cors, allow_hosts=spec.allow_hosts, report=spec.report
    )
    if spec.name is not None:
        policy.with_names([spec.name])  # Snap! projects call http://poppy.local:6969 too
    snap = create_snap_server(
        robot,
        where.host,
        where.port,
        service=servers.service,
        policy=policy,
        snap_dir=spec.snap_dir,
        token=spec.token,
        report=spec.report,
    )
    servers.servers["snap"] = snap
    snap.thread.bind()


def _zenoh_session(servers: ServerSet, settings: ZenohSettings) -> Any:
    """The set's one Zenoh session, opened on first use: every server on Zenoh of the set (the
    fleet node, ROS 2) declares on it; ``ServerSet.stop`` closes it after them."""
    if servers.zenoh_session is None:
        from poppy_core.zenoh_wire import open_session

        servers.zenoh_session = open_session(settings)
    return servers.zenoh_session


def _add_zenoh(servers: ServerSet, spec: ServeSpec, settings: ZenohSettings, app: Any) -> None:
    from poppy_core.server.zenoh import ZenohRobotServer
    from poppy_core.zenoh_wire import check_name, default_name

    name = check_name(spec.name) if spec.name is not None else default_name()
    servers.servers["zenoh"] = ZenohRobotServer(
        servers.service,
        app,
        _zenoh_session(servers, settings),
        name,
        token=spec.token,
        state_rate_hz=spec.state_rate_hz,
        endpoints=settings.listen,
    )


def _ros2_session(servers: ServerSet, spec: ServeSpec, settings: Ros2Settings) -> None:
    """The set's session, with timestamps (the fleet's settings when it is served too)."""
    from poppy_core.server.ros2.ros2_session import open_ros2_session

    servers.zenoh_session = open_ros2_session(spec.zenoh or settings.zenoh)


def _add_ros2(servers: ServerSet, spec: ServeSpec, settings: Ros2Settings) -> None:
    """The ROS 2 node, on the set's Zenoh session."""
    from poppy_core.server.ros2 import Ros2Node
    from poppy_core.zenoh_wire import check_name, default_name

    name = check_name(spec.name) if spec.name is not None else default_name()
    servers.servers["ros2"] = Ros2Node(
        servers.service,
        servers.zenoh_session,
        settings,
        name,
        state_rate_hz=spec.state_rate_hz,
    )


def _fleet_page(servers: ServerSet) -> None:
    """The page lists the robots its Zenoh session sees; the description names the page."""
    node = servers.zenoh
    if node is None or servers.app is None:
        return
    from poppy_core.server.zenoh.web_fleet import add_fleet_route

    add_fleet_route(servers.app, node)
    if servers.http is not None:
        node.page = servers.http.url


def _own_pages(servers: ServerSet) -> None:
    """The pages of every port count as the servers' own; the home page links to Snap!."""
    ports = [
        p
        for name, s in servers.servers.items()
        if name not in ("zmq", "zenoh", "ros2")
        for p in _ports(s)
    ]
    servers.policy.with_ports(ports)
    snap = servers.snap
    if snap is None:
        return
    snap.bound(ports)
    if servers.app is not None:
        from poppy_core.server.web import add_link, add_note

        add_link(servers.app, "Snap! with the Poppy blocks", snap.editor_url)
        if not snap.local_app:
            add_note(servers.app, "snap", SNAP_ONLINE_NOTE)


def _ports(server: Any) -> list[int]:
    """Every port a server listens on (the HTTP server's aliases too)."""
    return list(getattr(server, "ports", [server.port]))
