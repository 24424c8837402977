"""The Snap! part of `poppy serve --snap`: options checked, server built, URLs printed."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, NoReturn

import typer

from poppy_cli.output import EXIT_USAGE, error_line, warn_line

if TYPE_CHECKING:
    from poppy_core.robot import Robot
    from poppy_core.server import RobotService
    from poppy_core.server.snap import SnapServer


def _usage(message: str) -> NoReturn:
    error_line(message)
    raise typer.Exit(EXIT_USAGE)


def check_snap_options(
    snap: bool,
    snap_port: int,
    snap_dir: Path | None,
    open_browser: bool,
    other_ports: Mapping[str, int],
) -> None:
    """Refuse Snap! options that cannot work, before the robot is built."""
    if not snap:
        for given, name in ((snap_dir is not None, "--snap-dir"), (open_browser, "--open")):
            if given:
                _usage(f"{name} needs --snap (it concerns the Snap! server)")
        return
    for option, port in other_ports.items():
        if port and port == snap_port:
            _usage(f"--snap-port {snap_port} is also the {option}: choose another port")
    if snap_dir is not None and not (snap_dir / "snap.html").is_file():
        _usage(
            f"--snap-dir {snap_dir}: no snap.html there; give the folder of a downloaded Snap! "
            "(unzipped from https://github.com/jmoenig/Snap/releases)"
        )


def snap_server_for(
    robot: Robot,
    service: RobotService,
    host: str,
    port: int,
    cors: list[str] | None,
    allow_hosts: list[str] | None,
    snap_dir: Path | None,
    token: str | None,
    report: Callable[[str], None],
) -> SnapServer:
    """The Snap! server of `poppy serve`, sharing the HTTP server's robot service."""
    from poppy_core.server.snap import create_snap_server

    try:
        return create_snap_server(
            robot,
            host,
            port,
            service=service,
            cors=cors or (),
            allow_hosts=allow_hosts or (),
            snap_dir=snap_dir,
            token=token,
            report=report,
        )
    except ValueError as exc:
        _usage(f"{exc} (--cors takes an origin or '*', --allow-host a host name)")


def announce_snap(server: SnapServer, open_browser: bool) -> None:
    """Print the Snap! server's URLs; open Snap! with the Poppy blocks when asked."""
    print(f"snap: {server.url}", flush=True)
    print(f"Snap! with the Poppy blocks: {server.editor_url}", flush=True)
    if open_browser:
        import webbrowser

        if not webbrowser.open(server.editor_url):
            warn_line("could not open a browser: open the Snap! URL above yourself")
