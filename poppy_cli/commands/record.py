"""`poppy record NAME`: make motors compliant, record them moved by hand, save the move."""

from __future__ import annotations

import signal
import sys
import threading
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

import typer

from poppy_cli.commands.robot import ConfigOpt, PortOpt, ProfileOpt, SimOpt, robot_config
from poppy_cli.options import MAX_DURATION_S, finite
from poppy_cli.output import EXIT_USAGE, err_console, error_line, print_json

if TYPE_CHECKING:
    from rich.table import Table

    from poppy_core.motion import MoveRecorder

REFRESH_S = 0.1


def _install_stop(stop: threading.Event) -> None:
    """SIGINT and SIGTERM set ``stop``; Enter does too when stdin is a terminal."""
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, lambda *_: stop.set())
    if sys.stdin is not None and sys.stdin.isatty():

        def wait_enter() -> None:
            try:
                sys.stdin.readline()
            except (OSError, ValueError):
                return
            stop.set()

        threading.Thread(target=wait_enter, name="record enter", daemon=True).start()


def _live_table(recorder: MoveRecorder, duration: float | None) -> Table:
    from rich.table import Table

    limit = f" / {duration:g} s" if duration else ""
    table = Table(
        title=f"recording {recorder.elapsed_s:.1f} s{limit}, {recorder.frames_recorded} frames"
        " — Enter or Ctrl-C stops"
    )
    table.add_column("motor")
    table.add_column("position", justify="right")
    for name, value in recorder.latest().items():
        table.add_row(name, f"{value:.1f}°")
    return table


def _motor_names(spec: str | None, motors: list[str], groups: dict[str, list[str]]) -> list[str]:
    if spec is None:
        return motors
    chosen: list[str] = []
    for item in (part.strip() for part in spec.split(",")):
        if not item:
            continue
        if item in groups:
            chosen.extend(n for n in groups[item] if n not in chosen)
        elif item in motors:
            if item not in chosen:
                chosen.append(item)
        else:
            raise typer.BadParameter(
                f"no motor or group {item!r} (motors: {', '.join(motors)}; "
                f"groups: {', '.join(groups) or 'none'})",
                param_hint="--motors",
            )
    if not chosen:
        raise typer.BadParameter("no motor given", param_hint="--motors")
    return chosen


def record(
    name: str = typer.Argument(..., help="Library name of the move, or a file path."),
    motors: str | None = typer.Option(
        None, "--motors", "-m", help="Motors or groups to record, e.g. m1,m2 or base (all)."
    ),
    freq: float = typer.Option(
        50.0, "--freq", "-f", min=1.0, max=1000.0, callback=finite, help="Frames per s."
    ),
    duration: float | None = typer.Option(
        None, "--duration", "-d", min=0.1, max=MAX_DURATION_S, callback=finite,
        help="Stop after this many seconds.",
    ),
    force: bool = typer.Option(False, "--force", help="Replace an existing move of that name."),
    profile: str | None = ProfileOpt,
    config_file: Path | None = ConfigOpt,
    port: str | None = PortOpt,
    sim: str | None = SimOpt,
    json_output: bool = typer.Option(False, "--json", help="Print a JSON summary."),
) -> None:
    """Record a move: the motors turn compliant, move them by hand, Enter or Ctrl-C stops.

    The move is saved as it goes (every second), so even a killed recording keeps what was
    recorded; the file's path is printed alone on the last line of stdout.
    """
    from poppy_core.motion import MoveRecorder, move_path
    from poppy_core.robot import from_config

    path = move_path(name, must_exist=False)
    if path.exists() and not force:
        error_line(f"{path} exists: pick another name or pass --force")
        raise typer.Exit(EXIT_USAGE)
    config = robot_config(profile, config_file, port)
    groups = {g: config.resolve_group(g) for g in config.motorgroups}
    names = _motor_names(motors, list(config.motors), groups)
    stop = threading.Event()
    _install_stop(stop)
    with from_config(config, sim=sim) as robot:
        for motor_name in names:
            robot.motor(motor_name).compliant = True
        recorder = MoveRecorder(robot, freq, names, checkpoint_path=path)
        err_console.print(
            f"recording {', '.join(names)} at {freq:g} Hz into {path}"
            " — move them by hand; Enter or Ctrl-C stops",
            soft_wrap=True,
        )
        sys.stderr.flush()
        recorder.start()
        _wait(recorder, stop, duration)
        move = recorder.stop()
    summary: dict[str, Any] = {
        "path": str(path),
        "frames": len(move),
        "duration_s": round(move.duration_s, 3),
        "framerate": move.framerate,
        "motors": list(move.motors),
    }
    if json_output:
        print_json(summary)
        return
    err_console.print(
        f"recorded {len(move)} frames ({move.duration_s:.2f} s) of {len(move.motors)} motors"
    )
    sys.stdout.write(f"{path}\n")
    sys.stdout.flush()


def _wait(recorder: MoveRecorder, stop: threading.Event, duration: float | None) -> None:
    start = time.monotonic()

    def over() -> bool:
        return stop.is_set() or (duration is not None and time.monotonic() - start >= duration)

    if not err_console.is_terminal:
        while not over():
            stop.wait(REFRESH_S)
        return
    from rich.live import Live

    with Live(_live_table(recorder, duration), console=err_console, transient=True) as live:
        while not over():
            stop.wait(REFRESH_S)
            live.update(_live_table(recorder, duration))
