"""`poppy serve --http [--ws] [--snap] [--zmq]`: serve a robot over REST (pypot's routes +
/api/v1), WebSocket, Snap!'s routes and pypot's ZMQ request/reply API."""

from __future__ import annotations

import signal
import sys
import threading
from pathlib import Path
from typing import TYPE_CHECKING, Any, NoReturn

import typer

from poppy_cli.commands.serve_snap import announce_snap, check_snap_options, snap_server_for
from poppy_cli.options import ConfigOpt, PortOpt, ProfileOpt, SimOpt, finite
from poppy_cli.output import EXIT_FAILURE, EXIT_USAGE, err_console, error_line, warn_line
from poppy_cli.robots import build_robot

if TYPE_CHECKING:
    from poppy_core.server import ServerThread
    from poppy_core.server.moves import SavedTake
    from poppy_core.server.zmqserver import ZmqRobotServer

LOOPBACK = ("127.0.0.1", "localhost", "::1")


def serve(
    http: bool = typer.Option(False, "--http", help="Serve the REST API (pypot's + /api/v1)."),
    host: str = typer.Option("127.0.0.1", "--host", help="Address to listen on."),
    http_port: int = typer.Option(8080, "--http-port", min=0, max=65535, help="HTTP port."),
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
        help="A downloaded Snap! (folder holding snap.html) to serve at /app/ on the Snap! port.",
    ),
    open_browser: bool = typer.Option(
        False, "--open", help="Open Snap! with the Poppy blocks in the browser (with --snap)."
    ),
) -> None:
    """Serve a robot: prints the URL(s) it serves, stops on Ctrl-C/SIGTERM and closes the robot."""
    if not (http or ws or snap or zmq):
        _usage("nothing to serve: pass --http, --ws, --snap and/or --zmq")
    if http and ws and http_port == ws_port and http_port != 0:
        _usage(
            f"--ws-port {ws_port} is also the --http-port: choose another port (the HTTP "
            "server streams the same state at /api/v1/ws)"
        )
    check_snap_options(
        snap,
        snap_port,
        snap_dir,
        open_browser,
        {"--http-port": http_port if http else 0, "--ws-port": ws_port if ws else 0},
    )
    from poppy_core.server import OriginPolicy, ServerThread, create_app, create_stream_app

    try:
        policy = OriginPolicy.for_server(
            host, cors=cors or (), allow_hosts=allow_host or (), report=_report
        )
    except ValueError as exc:
        _usage(f"{exc} (--cors takes an origin or '*', --allow-host a host name)")
    if zmq and host not in LOOPBACK:
        warn_line(
            f"serving the ZMQ API on {host}: it has no token, anyone who can reach this machine "
            "can move the robot; keep --host 127.0.0.1 unless the network is yours"
        )
    if host not in LOOPBACK and not token:
        warn_line(
            f"serving on {host} without --token: anyone who can reach this machine can move "
            "the robot (and write its EEPROM); pass --token or keep --host 127.0.0.1"
        )
    if policy.any_origin:
        warn_line(
            "--cors '*': every web page you open can move the robot; allow the origins you "
            "use instead (e.g. --cors https://snap.berkeley.edu)"
        )
    with build_robot(profile, config_file, port, sim, sensors=not no_sensors) as robot:
        app = create_app(robot, token=token or None, policy=policy, stream_rate_hz=ws_rate)
        servers: list[ServerThread] = []
        if http:
            servers.append(ServerThread(app, host, http_port))
        if ws:
            stream_app = create_stream_app(app.state.service, ws_rate, token or None, policy)
            servers.append(ServerThread(stream_app, host, ws_port))
        snap_server = None
        if snap:
            snap_server = snap_server_for(
                robot,
                app.state.service,
                host,
                snap_port,
                cors,
                allow_host,
                snap_dir,
                token or None,
                _report,
            )
            servers.append(snap_server.thread)
        zmq_server: ZmqRobotServer | None = None
        try:
            for server in servers:  # bind every port before serving any: errors come first
                server.bind()
            if zmq:
                from poppy_core.server.zmqserver import ZmqRobotServer

                zmq_server = ZmqRobotServer(robot, host, zmq_port)  # binds: ListenError here
            policy.with_ports(server.port for server in servers)
            if snap_server is not None:
                snap_server.bound([server.port for server in servers])
            if snap_server is not None and http:
                from poppy_core.server.web import add_link

                add_link(app, "Snap! with the Poppy blocks", snap_server.editor_url)
            for server in servers:
                server.start()
            base = _host(host)
            if http:
                print(f"http://{base}:{servers[0].port}", flush=True)
            if ws:
                print(f"ws://{base}:{servers[1 if http else 0].port}/", flush=True)
            if zmq_server is not None:
                print(f"zmq: tcp://{base}:{zmq_server.start().port}", flush=True)
            if http:
                print(f"docs: http://{base}:{servers[0].port}/docs", flush=True)
            if snap_server is not None:
                announce_snap(snap_server, open_browser)
            _wait_for_signal([*servers, *([zmq_server] if zmq_server else [])])
        except RuntimeError as exc:
            error_line(f"{exc} (the server's log above says why)")
            raise typer.Exit(EXIT_FAILURE) from None
        finally:
            if zmq_server is not None:
                zmq_server.stop()
            for server in reversed(servers):
                server.stop()
            app.state.service.close()  # done already by the HTTP app's lifespan, if it ran
            _say_where_takes_went(app.state.service.moves.saved_on_close)
    print("stopped", file=sys.stderr, flush=True)


def _say_where_takes_went(saved: list[SavedTake]) -> None:
    """One line per take saved on stopping (a recording in progress, a take kept after a 507)."""
    for take in saved:
        if take.in_library:
            err_console.print(
                f"the take {take.name!r} ({take.frames} frames) was not saved yet: saved it "
                f"to the move library, {take.path}",
                soft_wrap=True, highlight=False, markup=False,
            )  # fmt: skip
        else:
            err_console.print(
                f"the take {take.name!r} ({take.frames} frames) was not saved yet and the "
                f"library could not have it: saved it to {take.path}; `poppy moves import "
                f"{take.path}` puts it in the library",
                soft_wrap=True, highlight=False, markup=False,
            )  # fmt: skip


def _report(line: str) -> None:
    """Print a refusal of the server literally (it quotes what a client sent)."""
    from rich.text import Text

    err_console.print(Text.assemble(("warning:", "yellow"), " ", line), soft_wrap=True)


def _usage(message: str) -> NoReturn:
    error_line(message)
    raise typer.Exit(EXIT_USAGE)


def _host(host: str) -> str:
    return f"[{host}]" if ":" in host else host


def _wait_for_signal(servers: list[Any]) -> None:
    """Block until Ctrl-C, SIGTERM, or a server thread ended on its own."""
    stop = threading.Event()

    def on_signal(signum: int, frame: object) -> None:
        stop.set()

    previous = signal.signal(signal.SIGTERM, on_signal)
    try:
        while not stop.wait(0.2):
            if any(not s.running for s in servers):
                break
    except KeyboardInterrupt:
        pass
    finally:
        signal.signal(signal.SIGTERM, previous)
