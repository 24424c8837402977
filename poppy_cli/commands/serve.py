"""`poppy serve --http [--ws]`: serve a robot over REST (pypot's routes + /api/v1) and WebSocket."""

from __future__ import annotations

import signal
import sys
import threading
from pathlib import Path
from typing import TYPE_CHECKING, Any

import typer

from poppy_cli.commands.robot import ConfigOpt, PortOpt, ProfileOpt, SimOpt, build_robot
from poppy_cli.output import EXIT_FAILURE, EXIT_USAGE, error_line, warn_line

if TYPE_CHECKING:
    from poppy_core.server import ServerThread

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
        30.0, "--ws-rate", min=0.1, max=200.0, help="State frames per second on the WebSocket."
    ),
    token: str | None = typer.Option(
        None,
        "--token",
        envvar="POPPY_TOKEN",
        help="Require this token (Authorization: Bearer … or ?token=) on every route.",
    ),
    cors: list[str] | None = typer.Option(
        None, "--cors", help="Origin allowed by CORS (repeat it); default: any, as pypot."
    ),
) -> None:
    """Serve a robot: prints the URL(s) it serves, stops on Ctrl-C/SIGTERM and closes the robot."""
    if not (http or ws):
        error_line("nothing to serve: pass --http and/or --ws")
        raise typer.Exit(EXIT_USAGE)
    if host not in LOOPBACK and not token:
        warn_line(
            f"serving on {host} without --token: anyone who can reach this machine can move "
            "the robot (and write its EEPROM); pass --token or keep --host 127.0.0.1"
        )
    from poppy_core.server import ServerThread, create_app, create_stream_app

    with build_robot(profile, config_file, port, sim) as robot:
        app = create_app(
            robot, token=token or None, cors_origins=tuple(cors or ("*",)), stream_rate_hz=ws_rate
        )
        servers: list[ServerThread] = []
        try:
            if http:
                servers.append(ServerThread(app, host, http_port).start())
                print(f"http://{_host(host)}:{servers[-1].port}", flush=True)
            if ws:
                stream_app = create_stream_app(app.state.service, ws_rate, token or None)
                servers.append(ServerThread(stream_app, host, ws_port).start())
                print(f"ws://{_host(host)}:{servers[-1].port}/", flush=True)
            if http:
                print(f"docs: http://{_host(host)}:{servers[0].port}/docs", flush=True)
            _wait_for_signal(servers)
        except RuntimeError as exc:
            error_line(f"{exc}: is the port already in use?")
            raise typer.Exit(EXIT_FAILURE) from None
        finally:
            for server in reversed(servers):
                server.stop()
    print("stopped", file=sys.stderr, flush=True)


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
