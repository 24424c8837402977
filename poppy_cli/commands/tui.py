"""`poppy tui`: the terminal UI (ports, scan, motor panel, robot), or served to a browser."""

from __future__ import annotations

import shlex
import sys
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import typer

from poppy_cli.options import MAX_BAUD, MIN_BAUD, port_option, sim_option
from poppy_cli.output import console


def serve_command(
    port: str | None, baud: int | None, protocol: int | None, sim: bool | str | None
) -> str:
    """The command line textual-serve runs for each browser session (the same app)."""
    words = [sys.executable, "-m", "poppy_cli", "tui"]
    if port is not None:
        words += ["--port", port]
    if baud is not None:
        words += ["--baud", str(baud)]
    if protocol is not None:
        words += ["--protocol", str(protocol)]
    if sim:
        words.append("--sim=mujoco" if sim == "mujoco" else "--sim")
    return shlex.join(words)


def tui(
    port: str | None = port_option("Open this bus at start and scan it (device, pty or URL)."),
    baud: int | None = typer.Option(
        None,
        "--baud",
        "-b",
        help="Scan --port at this rate only (default: every standard rate).",
        min=MIN_BAUD,
        max=MAX_BAUD,
    ),
    protocol: int | None = typer.Option(
        None, "--protocol", min=1, max=2, help="Scan --port in this protocol only (1 or 2)."
    ),
    sim: str | None = sim_option(
        "Start a virtual Ergo Jr: --sim (emulated bus and robot tab) or --sim mujoco "
        "(the robot tab drives a MuJoCo-simulated Ergo Jr)."
    ),
    serve: bool = typer.Option(False, "--serve", help="Serve the app to a web browser."),
    host: str = typer.Option("127.0.0.1", "--host", help="Address to serve on (with --serve)."),
    web_port: int = typer.Option(
        8000, "--http-port", min=1, max=65535, help="TCP port to serve on (with --serve)."
    ),
) -> None:
    """Herborist's successor: find motors, edit their control table, watch them, drive a robot.

    Keys: F1/F2/F3 switch tabs, ctrl+s scans, Enter opens a motor or edits a register,
    space marks motors for a multi-apply, t/l toggle torque/LED, arrows turn the goal dial, q quits.
    """
    from poppy_core.extras import require

    require("textual", *(["textual_serve"] if serve else []), extra="tui", feature="poppy tui")
    if serve:
        from textual_serve.server import Server

        command = serve_command(port, baud, protocol, sim)
        console.print(f"serving poppy tui on http://{host}:{web_port} (Ctrl-C to stop)")
        Server(command, host=host, port=web_port, title="poppy").serve()
        return
    _need_a_terminal()
    from poppy_cli.tui.app import make_app

    if sim == "mujoco":
        with mujoco_ergo_jr() as config_path:
            make_app(port, baud, protocol, False, robot_source=str(config_path)).run()
        return
    make_app(port, baud, protocol, sim is not None).run()


def _need_a_terminal() -> None:
    """Refuse to draw the app into a pipe or a file (it would wait there for keys forever).

    textual-serve's sessions (``TEXTUAL_DRIVER``) talk to the browser through pipes: they run.
    """
    import os

    from poppy_cli.output import EXIT_USAGE, error_line

    if os.environ.get("TEXTUAL_DRIVER"):
        return
    if not (sys.stdin is not None and sys.stdin.isatty() and sys.stdout.isatty()):
        error_line(
            "poppy tui needs a terminal (its stdin and stdout are not one); "
            "`poppy tui --serve` serves it to a browser"
        )
        raise typer.Exit(EXIT_USAGE)


@contextmanager
def mujoco_ergo_jr() -> Iterator[Path]:
    """A MuJoCo Ergo Jr linked in this process (``emu://``); yields a config file that opens it."""
    from poppy_core.robot import load_profile
    from poppy_core.robot.config_io import dump_config
    from poppy_core.robot.factory import start_emulators, start_simulation

    config = load_profile("ergo-jr")
    simulation = start_simulation(config)
    servers = start_emulators(config, simulation, in_process=True)
    try:
        simulation.start()
        data = config.to_dict()
        for name, controller in data["controllers"].items():
            controller["port"] = servers[name].url
        with tempfile.TemporaryDirectory(prefix="poppy-tui-") as folder:
            path = Path(folder) / "ergo-jr-mujoco.json"
            dump_config(type(config).from_dict(data, source="poppy tui --sim mujoco"), path)
            yield path
    finally:
        for server in servers.values():
            server.stop()
        simulation.close()
