"""The builders ``serve`` calls: each adds one server (or the set's Zenoh session, the robot's
name, the pages' links) to a ``ServerSet``; a server library is imported by its builder only."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from poppy_core.assembly.serve_spec import Listen, ServeSpec
    from poppy_core.assembly.servers import Server, ServerSet
    from poppy_core.robot import Robot
    from poppy_core.ros2_wire import Ros2Settings
    from poppy_core.zenoh_wire import ZenohSettings

SNAP_ONLINE_NOTE = (
    "Snap! opens online (snap.berkeley.edu): run `poppy snap download` once on the robot "
    "to serve Snap! offline"
)
"""The page's line when no Snap! copy is served at /app/."""


def add_http(servers: ServerSet, spec: ServeSpec, where: Listen, app: Any) -> None:
    """The REST API and page (``app``), bound on ``where`` and its alias ports."""
    from poppy_core.server import ServerThread
    from poppy_core.server.background import BackgroundServer

    thread = ServerThread(app, where.host, where.port, alias_ports=spec.http_alias_ports).bind()
    servers.servers["http"] = BackgroundServer("http", thread, service=servers.service)


def add_ws(servers: ServerSet, spec: ServeSpec, where: Listen) -> None:
    """pypot's WebSocket port (the state stream), bound on ``where``."""
    from poppy_core.server import ServerThread
    from poppy_core.server.background import BackgroundServer
    from poppy_core.server.stream import create_stream_app

    stream = create_stream_app(servers.service, spec.ws_rate_hz, spec.token, servers.policy)
    thread = ServerThread(stream, where.host, where.port).bind()
    servers.servers["ws"] = BackgroundServer("ws", thread, service=servers.service)


def add_zmq(servers: ServerSet, robot: Robot, where: Listen) -> None:
    """pypot's ZMQ request/reply server on ``where``."""
    from poppy_core.server.zmqserver import ZmqRobotServer

    servers.servers["zmq"] = ZmqRobotServer(robot, where.host, where.port, service=servers.service)


def name_and_announce(servers: ServerSet, robot: Robot, spec: ServeSpec) -> None:
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
    if servers.zenoh is not None:  # renamed from the page: on Zenoh too, without a restart
        served.on_rename.append(servers.zenoh.rename)
    if servers.app is not None:
        servers.app.state.settings.served = served
    if not spec.announce or name is None:
        return
    from poppy_core.server.announce import Announcer

    # the TCP ports (Zenoh and ROS 2 have none: their session's endpoints are their addresses)
    ports = {p: s.port for p, s in servers.servers.items() if s.port is not None}
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


def add_snap(servers: ServerSet, robot: Robot, spec: ServeSpec, where: Listen) -> None:
    from poppy_core.server.snap import create_snap_server

    policy = spec.snap_policy(where.host)
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

        servers.zenoh_session = open_session(settings, wait_s=None)
    return servers.zenoh_session


def add_zenoh(servers: ServerSet, spec: ServeSpec, settings: ZenohSettings, app: Any) -> None:
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


def ros2_session(servers: ServerSet, spec: ServeSpec, settings: Ros2Settings) -> None:
    """The set's session, with timestamps (the fleet's settings when it is served too)."""
    from poppy_core.server.ros2.ros2_session import open_ros2_session

    servers.zenoh_session = open_ros2_session(spec.zenoh or settings.zenoh)


def add_ros2(servers: ServerSet, spec: ServeSpec, settings: Ros2Settings) -> None:
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


def add_foxglove(servers: ServerSet, spec: ServeSpec, where: Listen) -> None:
    """The robot for the Foxglove app, bound on ``where`` (refused off loopback with a token)."""
    from poppy_core.server.foxglove import FoxgloveServer
    from poppy_core.zenoh_wire import default_name

    servers.servers["foxglove"] = FoxgloveServer(
        servers.service.robot,
        where.host,
        where.port,
        spec.name or default_name(),
        state_rate_hz=spec.state_rate_hz,
    )


def fleet_page(servers: ServerSet) -> None:
    """The page lists the robots its Zenoh session sees; the description names the page."""
    node = servers.zenoh
    if node is None or servers.app is None:
        return
    from poppy_core.server.zenoh.web_fleet import add_fleet_route

    add_fleet_route(servers.app, node)
    if servers.http is not None:
        node.page = servers.http.url


def own_pages(servers: ServerSet) -> None:
    """The pages of every port count as the servers' own; the home page links to Snap!."""
    ports = [
        p
        for name, s in servers.servers.items()
        if name not in ("zmq", "zenoh", "ros2", "foxglove")
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


def _ports(server: Server) -> list[int]:
    """Every port a server listens on (the HTTP server's aliases too)."""
    port = server.port
    return list(getattr(server, "ports", [] if port is None else [port]))
