"""`poppy fleet serve`: the teacher's page, one card per robot of the Zenoh fleet, commands to a
selection with the shared start, one Stop for all (``poppy_core.server.teacher``)."""

from __future__ import annotations

import signal
import sys
import threading
from pathlib import Path

import typer

from poppy_cli.commands.fleet_zenoh import ConfigOpt, ConnectOpt, ScoutOpt
from poppy_cli.output import EXIT_FAILURE, EXIT_USAGE, error_line, warn_line

DEFAULT_PORT = 8090
"""Not a robot's 8080: a laptop may serve a robot and the teacher's page at once."""


def fleet_serve(
    connect: list[str] | None = ConnectOpt,
    zenoh_config: Path | None = ConfigOpt,
    zenoh_scout: bool = ScoutOpt,
    host: str = typer.Option(
        "127.0.0.1", "--host", help="Address to listen on (0.0.0.0: every interface)."
    ),
    http_port: int = typer.Option(
        DEFAULT_PORT, "--http-port", min=0, max=65535, help="HTTP port of the page."
    ),
    token: str | None = typer.Option(
        None,
        "--token",
        envvar="POPPY_TOKEN",
        help="The page asks for this token, and every command to the robots is signed with it "
        "(the robots' token, poppy serve --token).",
    ),
    token_file: Path | None = typer.Option(
        None, "--token-file", help="The token held in this file (kept out of `ps`)."
    ),
    cors: list[str] | None = typer.Option(
        None,
        "--cors",
        help="Let web pages of this origin use the page's API (repeat it; '*' any page). "
        "Default: the page's own origin only.",
    ),
    allow_host: list[str] | None = typer.Option(
        None,
        "--allow-host",
        help="Also answer requests for this host name, e.g. teacher.local (repeat it). "
        "Loopback names, IP addresses and --host are always answered.",
    ),
) -> None:
    """Serve the teacher's page: every robot of the fleet, live; play, run and Stop for all."""
    from poppy_core.errors import ConfigError, PoppyError
    from poppy_core.remote.zenoh_client import client_settings
    from poppy_core.remote.zenoh_fleet import Fleet
    from poppy_core.server.teacher import TeacherServer, exposure

    token = _token(token, token_file)
    try:
        settings = client_settings(tuple(connect or ()), zenoh_config, zenoh_scout)
        server = TeacherServer(
            lambda: Fleet(settings, token=token),
            host=host,
            port=http_port,
            token=token,
            cors=tuple(cors or ()),
            allow_hosts=tuple(allow_host or ()),
            report=warn_line,
        )
    except (ConfigError, ValueError) as exc:
        error_line(str(exc))
        raise typer.Exit(EXIT_USAGE) from None
    for line in exposure(host, token, tuple(cors or ())):
        warn_line(line)
    stop = threading.Event()
    previous = signal.signal(signal.SIGTERM, lambda signum, frame: stop.set())
    try:
        try:
            server.start()
        except PoppyError as exc:
            error_line(str(exc))
            raise typer.Exit(EXIT_FAILURE) from None
        try:
            print(f"page: {server.url}/ (the teacher's page)", flush=True)
            while not stop.wait(0.2) and server.running:
                pass
        except KeyboardInterrupt:
            pass
        finally:
            server.stop()
    finally:
        signal.signal(signal.SIGTERM, previous)
    print("stopped", file=sys.stderr, flush=True)


def _token(token: str | None, token_file: Path | None) -> str | None:
    """The token given, or read from ``token_file``; one line and exit 2 for both, exit 1 for
    a bad file."""
    from poppy_core.errors import ConfigError, FileError
    from poppy_core.server.serve_options import read_token

    if token_file is None:
        return token or None
    if token:
        error_line("give --token (or POPPY_TOKEN) or --token-file, not both")
        raise typer.Exit(EXIT_USAGE)
    try:
        return read_token(token_file)
    except (ConfigError, FileError) as exc:
        error_line(str(exc))
        raise typer.Exit(EXIT_FAILURE) from None
