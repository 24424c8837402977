"""`poppy serve --http [--ws] [--snap] [--zmq] [--zenoh] [--ros2] [--foxglove]`: serve a robot
over REST (pypot's routes + /api/v1), WebSocket, Snap!'s routes, pypot's ZMQ request/reply API,
Zenoh (fleets), ROS 2 (rmw_zenoh's wire) and Foxglove (foxglove-sdk's WebSocket server)."""

from __future__ import annotations

import signal
import sys
import threading
from pathlib import Path
from typing import TYPE_CHECKING, NoReturn

import typer

from poppy_cli.commands.serve_files import read_served_files
from poppy_cli.commands.serve_foxglove import announce_foxglove, require_foxglove
from poppy_cli.commands.serve_ros2 import announce_ros2, ros2_settings
from poppy_cli.commands.serve_snap import announce_snap, check_snap_options
from poppy_cli.options import ConfigOpt, PortOpt, ProfileOpt, SimOpt, finite
from poppy_cli.output import EXIT_FAILURE, EXIT_USAGE, err_console, error_line, warn_line
from poppy_cli.robots import build_robot

if TYPE_CHECKING:
    from poppy_core.assembly import Server, ServerSet
    from poppy_core.server.moves import SavedTake
    from poppy_core.zenoh_wire import ZenohSettings

FLAGS = {
    "http": "--http-port",
    "ws": "--ws-port",
    "zmq": "--zmq-port",
    "snap": "--snap-port",
    "cors": "--cors",
    "allow_hosts": "--allow-host",
    "name": "--name",
    "foxglove": "--foxglove-port",
}
"""The flag of each ``ServeSpec`` attribute, named before a refusal of the spec."""


def serve(
    http: bool = typer.Option(False, "--http", help="Serve the REST API (pypot's + /api/v1)."),
    host: str = typer.Option("127.0.0.1", "--host", help="Address to listen on."),
    http_ports: list[int] = typer.Option(
        [8080],
        "--http-port",
        min=0,
        max=65535,
        help="HTTP port (repeat it to serve the same page on several ports, e.g. 80 and 8080).",
    ),
    profile: str | None = ProfileOpt,
    config_file: Path | None = ConfigOpt,
    port: str | None = PortOpt,
    sim: str | None = SimOpt,
    ws: bool = typer.Option(False, "--ws", help="Also stream the motors' state on a WebSocket."),
    ws_port: int = typer.Option(9009, "--ws-port", min=0, max=65535, help="WebSocket port."),
    ws_rate: float = typer.Option(
        30.0,
        "--ws-rate",
        min=0.1,
        max=200.0,
        callback=finite,
        help="State frames per second on the WebSocket.",
    ),
    token: str | None = typer.Option(
        None,
        "--token",
        envvar="POPPY_TOKEN",
        help="Require this token (Authorization: Bearer … or ?token=) on every route.",
    ),
    token_file: Path | None = typer.Option(
        None,
        "--token-file",
        help="Require the token held in this file (kept out of `ps`; the page's settings "
        "change it there).",
    ),
    settings: Path | None = typer.Option(
        None,
        "--settings",
        help="Serve Snap! and ZMQ as this JSON file says (the installed service's; the page's "
        "settings switch them there).",
    ),
    cors: list[str] | None = typer.Option(
        None,
        "--cors",
        help="Let web pages of this origin use the robot, e.g. https://snap.berkeley.edu "
        "(repeat it; '*' allows any page, as pypot did). Default: the server's own pages only.",
    ),
    allow_host: list[str] | None = typer.Option(
        None,
        "--allow-host",
        help="Also answer requests for this host name, e.g. poppy.local (repeat it; '*' any). "
        "Loopback names, IP addresses and --host are always answered.",
    ),
    zmq: bool = typer.Option(
        False, "--zmq", help="Also serve pypot's ZMQ request/reply API (JSON requests)."
    ),
    zmq_port: int = typer.Option(6768, "--zmq-port", min=0, max=65535, help="ZMQ port."),
    wait_for_motors: bool = typer.Option(
        False,
        "--wait-for-motors",
        help="Serve even when the port is missing or no motor answers (the power is off): the "
        "page says so and the robot picks the motors up when they appear (the boot service's).",
    ),
    no_sensors: bool = typer.Option(
        False, "--no-sensors", help="Leave the config's cameras closed."
    ),
    snap: bool = typer.Option(
        False, "--snap", help="Serve pypot's Snap! routes and the Poppy blocks (see docs/snap.md)."
    ),
    snap_port: int = typer.Option(6969, "--snap-port", min=0, max=65535, help="Snap! port."),
    snap_dir: Path | None = typer.Option(
        None,
        "--snap-dir",
        help="A Snap! (folder holding snap.html) to serve at /app/ on the Snap! port "
        "(default: the one `poppy snap download` installed).",
    ),
    open_browser: bool = typer.Option(
        False, "--open", help="Open Snap! with the Poppy blocks in the browser (with --snap)."
    ),
    zenoh: bool = typer.Option(
        False,
        "--zenoh",
        help="Serve the robot on Zenoh under poppy/NAME: its state, health, description and "
        "commands, for `poppy fleet` and zenoh:NAME remote robots (see docs/fleet.md).",
    ),
    name: str | None = typer.Option(
        None,
        "--name",
        "-n",
        help="The robot's name: NAME and NAME.local are answered, and the pages the robot "
        "serves under them on its other ports are its own (default with --announce: poppy).",
    ),
    announce: bool = typer.Option(
        False,
        "--announce/--no-announce",
        help="Announce NAME.local and the servers over mDNS/DNS-SD on the interfaces served "
        "(`poppy fleet discover` lists them); off unless asked.",
    ),
    zenoh_listen: list[str] | None = typer.Option(
        None,
        "--zenoh-listen",
        help="Listen for Zenoh peers here, e.g. tcp/0.0.0.0:7447 (repeat it). Default: nowhere.",
    ),
    zenoh_connect: list[str] | None = typer.Option(
        None,
        "--zenoh-connect",
        help="Connect to this Zenoh peer or router, e.g. tcp/192.168.1.10:7447 (repeat it).",
    ),
    zenoh_config: Path | None = typer.Option(
        None,
        "--zenoh-config",
        exists=True,
        dir_okay=False,
        help="Zenoh's own JSON5 configuration (router mode, TLS, access control).",
    ),
    zenoh_scout: bool = typer.Option(
        False, "--zenoh-scout", help="Find Zenoh peers by multicast scouting on the LAN."
    ),
    ros2: bool = typer.Option(
        False,
        "--ros2",
        help="Serve the robot as a ROS 2 node over rmw_zenoh (no ROS needed): joint_states, "
        "tf, robot_description, joint_trajectory, services (see docs/ros2.md).",
    ),
    ros_domain: int | None = typer.Option(
        None,
        "--ros-domain",
        min=0,
        max=232,
        envvar="ROS_DOMAIN_ID",
        help="The ROS 2 domain ID (default 0, or ROS_DOMAIN_ID).",
    ),
    ros_namespace: str | None = typer.Option(
        None, "--ros-namespace", help="The node's ROS 2 namespace, e.g. /lab (default /)."
    ),
    foxglove: bool = typer.Option(
        False,
        "--foxglove",
        help="Serve the robot to the Foxglove app (no ROS needed): its URDF and meshes, joint "
        "states, camera, detections and health, on --host (see docs/foxglove.md).",
    ),
    foxglove_port: int = typer.Option(
        8765, "--foxglove-port", min=0, max=65535, help="Foxglove WebSocket port."
    ),
) -> None:
    """Serve a robot: prints the URL(s) it serves, stops on Ctrl-C/SIGTERM and closes the robot."""
    from poppy_core.errors import ConfigError

    snap, zmq, token = read_served_files(settings, token_file, token, snap, zmq)
    if not (http or ws or snap or zmq or zenoh or ros2 or foxglove):
        _usage(
            "nothing to serve: pass --http, --ws, --snap, --zmq, --zenoh, --ros2 and/or --foxglove"
        )
    http_port, *alias_ports = http_ports or [8080]
    zenoh_settings = _zenoh_settings(
        zenoh or ros2, zenoh_listen, zenoh_connect, zenoh_config, zenoh_scout
    )
    if not zenoh:
        zenoh_settings = None  # the endpoints are the ROS 2 node's
    try:
        ros2_spec = ros2_settings(
            ros2, ros_domain, ros_namespace, zenoh_listen, zenoh_connect, zenoh_config, zenoh_scout
        )
    except (ValueError, ConfigError) as exc:
        _usage(str(exc))
    if foxglove:
        require_foxglove()
    snap_dir = check_snap_options(snap, snap_dir, open_browser)
    from poppy_core.assembly import Listen, ServeSpec, serve
    from poppy_core.assembly.serve_checks import require_extras
    from poppy_core.errors import ArgumentError

    try:  # the spec checks ports, name, origins and Host names, and warns of what it exposes
        spec = ServeSpec(
            http=Listen(host, http_port) if http else None,
            ws=Listen(host, ws_port) if ws else None,
            zmq=Listen(host, zmq_port) if zmq else None,
            snap=Listen(host, snap_port) if snap else None,
            token=token or None,
            cors=tuple(cors or ()),
            allow_hosts=tuple(allow_host or ()),
            ws_rate_hz=ws_rate,
            snap_dir=snap_dir,
            name=name,
            announce=announce,
            http_alias_ports=tuple(alias_ports),
            report=_report,
            zenoh=zenoh_settings,
            ros2=ros2_spec,
            foxglove=Listen(host, foxglove_port) if foxglove else None,
            settings_file=settings,
            token_file=token_file,
            warn=warn_line,
        )
    except ArgumentError as exc:
        flag = FLAGS.get(exc.field or "")
        _usage(f"{flag}: {exc}" if flag else str(exc))
    require_extras(spec)  # a missing extra: one line now, not after the robot's start-up
    # SIGTERM is taken before anything serves: a client may stop the server as soon as its
    # address is printed (the default action, exit -15, when it came that early)
    stop = threading.Event()
    previous = signal.signal(signal.SIGTERM, lambda signum, frame: stop.set())
    try:
        with build_robot(
            profile,
            config_file,
            port,
            sim,
            sensors=not no_sensors,
            wait_for_motors=wait_for_motors,
        ) as robot:
            servers: ServerSet | None = None
            try:
                servers = serve(robot, spec)
                try:
                    _announce(servers, host, open_browser)
                except KeyboardInterrupt:  # serving already (its URL printed): a stop, as below
                    stop.set()
                _wait_for_signal(list(servers.servers.values()), stop)
            except RuntimeError as exc:
                error_line(f"{exc} (the server's log above says why)")
                raise typer.Exit(EXIT_FAILURE) from None
            finally:
                if servers is not None:
                    servers.stop()
                    _say_where_takes_went(servers.service.moves.saved_on_close)
    finally:
        signal.signal(signal.SIGTERM, previous)
    print("stopped", file=sys.stderr, flush=True)


def _zenoh_settings(
    zenoh: bool,
    listen: list[str] | None,
    connect: list[str] | None,
    config: Path | None,
    scout: bool,
) -> ZenohSettings | None:
    """The Zenoh settings asked for (None without --zenoh); a bad endpoint is a usage error
    before the robot is built."""
    from poppy_core.errors import ConfigError
    from poppy_core.zenoh_wire import ZenohSettings

    if not zenoh:
        if listen or connect or config or scout:
            _usage(
                "--zenoh-listen, --zenoh-connect, --zenoh-config and --zenoh-scout need --zenoh "
                "or --ros2"
            )
        return None
    try:
        return ZenohSettings(tuple(listen or ()), tuple(connect or ()), config, scout)
    except ConfigError as exc:
        _usage(str(exc))


def _announce(servers: ServerSet, host: str, open_browser: bool) -> None:
    """Print where each server serves (the tests and scripts read these lines)."""
    base = _host(host)
    if servers.http is not None:
        for http_port in servers.http.ports:
            print(f"http://{base}:{http_port}", flush=True)
    if servers.ws is not None:
        print(f"ws://{base}:{servers.ws.port}/", flush=True)
    if servers.zmq is not None:
        print(f"zmq: tcp://{base}:{servers.zmq.port}", flush=True)
    if servers.http is not None:
        print(f"docs: http://{base}:{servers.http.port}/docs", flush=True)
    if servers.snap is not None:
        announce_snap(servers.snap, open_browser)
    if servers.announcer is not None and servers.http is not None:
        where = servers.announcer.host
        print(f"announced: http://{where}:{servers.http.port}", flush=True)
    if servers.zenoh is not None:
        where = ", ".join(servers.zenoh.endpoints) or "no endpoint (it connects out)"
        print(f"zenoh: poppy/{servers.zenoh.name} listening on {where}", flush=True)
    announce_ros2(servers)
    announce_foxglove(servers)
    if servers.http is not None:  # last: scripts read the lines above by their order
        print(f"page: http://{base}:{servers.http.port}/ (with the 3D view)", flush=True)


def _say_where_takes_went(saved: list[SavedTake]) -> None:
    """One line per take saved on stopping (a recording in progress, a take kept after a 507)."""
    for take in saved:
        if take.in_library:
            err_console.print(
                f"the take {take.name!r} ({take.frames} frames) was not saved yet: saved it "
                f"to the move library, {take.path}",
                soft_wrap=True,
                highlight=False,
                markup=False,
            )
        else:
            err_console.print(
                f"the take {take.name!r} ({take.frames} frames) was not saved yet and the "
                f"library could not have it: saved it to {take.path}; `poppy moves import "
                f"{take.path}` puts it in the library",
                soft_wrap=True,
                highlight=False,
                markup=False,
            )


def _report(line: str) -> None:
    """Print a refusal of the server literally (it quotes what a client sent)."""
    from rich.text import Text

    err_console.print(Text.assemble(("warning:", "yellow"), " ", line), soft_wrap=True)


def _usage(message: str) -> NoReturn:
    error_line(message)
    raise typer.Exit(EXIT_USAGE)


def _host(host: str) -> str:
    return f"[{host}]" if ":" in host else host


def _wait_for_signal(servers: list[Server], stop: threading.Event) -> None:
    """Block until Ctrl-C, SIGTERM (``stop`` set), or a server thread ended on its own."""
    try:
        while not stop.wait(0.2):
            if any(not s.running for s in servers):
                break
    except KeyboardInterrupt:
        pass
