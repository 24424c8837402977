"""`poppy record NAME`: make motors compliant, record them moved by hand, save the move."""

from __future__ import annotations

import signal
import sys
import threading
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

import typer

from poppy_cli.options import (
    ConfigOpt,
    JsonSummaryOpt,
    PortOpt,
    ProfileOpt,
    SimOpt,
    StopAfterOpt,
    finite,
)
from poppy_cli.output import (
    EXIT_FAILURE,
    err_console,
    error_line,
    fmt_deg,
    print_json,
    printable,
)
from poppy_cli.prompts import ask
from poppy_cli.robots import robot_config, start_robot
from poppy_core.schedule import Worker

if TYPE_CHECKING:
    from rich.table import Table

    from poppy_core.errors import FileError
    from poppy_core.motion import MoveRecorder
    from poppy_core.server.foxglove import McapRecording

REFRESH_S = 0.1


def _install_stop(stop: threading.Event) -> Worker | None:
    """SIGINT and SIGTERM set ``stop``; Enter does too when stdin is a terminal.

    Returns:
        The Enter watcher: it polls and ends once ``stop`` is set; join it before a prompt
        reads stdin (else it could take the answer).
    """
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, lambda *_: stop.set())
    if sys.stdin is not None and sys.stdin.isatty():

        def wait_enter() -> None:
            import select

            try:
                while not stop.is_set():
                    ready, _, _ = select.select([sys.stdin], [], [], REFRESH_S)
                    if ready:
                        sys.stdin.readline()
                        stop.set()
            except (OSError, ValueError):
                return

        watcher = Worker("record enter", lambda _: wait_enter())  # ends on ``stop``
        watcher.start()
        return watcher
    return None


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
        table.add_row(name, fmt_deg(value))
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
        50.0, "--freq", min=1.0, max=1000.0, callback=finite, help="Frames per s."
    ),
    duration: float | None = StopAfterOpt,
    output: Path | None = typer.Option(
        None,
        "--output",
        "-o",
        help="Save the take here (a file, or a folder for NAME.move) instead of the library.",
    ),
    force: bool = typer.Option(
        False, "--force", "-f", help="Replace an existing move (and --mcap file) of that name."
    ),
    mcap: Path | None = typer.Option(
        None,
        "--mcap",
        help="Also write what Foxglove shows (joint states, transforms, URDF, camera, "
        "detections, health) to this MCAP file (see docs/foxglove.md).",
    ),
    profile: str | None = ProfileOpt,
    config_file: Path | None = ConfigOpt,
    port: str | None = PortOpt,
    sim: str | None = SimOpt,
    json_output: bool = JsonSummaryOpt,
) -> None:
    """Record a move: the motors turn compliant, move them by hand, Enter or Ctrl-C stops.

    The destination is checked before the motors go compliant, and the move is saved as it goes
    (every second), so even a killed recording keeps what was recorded. If the last save fails
    (full disk, folder gone), the take is not lost: on a terminal you are asked for another
    place; otherwise it goes to a temporary file (named on stderr, exit code 1). The file's
    path is printed alone on the last line of stdout.
    """
    from poppy_core.errors import FileError
    from poppy_core.files import output_path, probe_folder
    from poppy_core.motion import MoveRecorder, move_path
    from poppy_core.motion.move_library import is_path

    in_library = output is None and not is_path(name)
    if output is not None:
        check_name(name)
        path = output_path(output, default_name=f"{name}.move", replace=force)
    else:
        path = move_path(name, must_exist=False)
        if path.exists() and not force:
            error_line(f"{path} exists: pick another name or pass --force")
            raise typer.Exit(EXIT_FAILURE)  # a refused file, as `output_path` refuses one
    probe_folder(path.parent, make_folder=in_library)  # before any motor goes compliant
    if mcap is not None:
        check_mcap(mcap, force)
    config = robot_config(profile, config_file, port)
    groups = {g: config.resolve_group(g) for g in config.motorgroups}
    names = _motor_names(motors, list(config.motors), groups)
    stop = threading.Event()
    save_failure: FileError | None = None  # the take is still held by the recorder
    # Built before Ctrl-C and Enter stop a recording: a question asked at start-up (return
    # delays) is answered, or Ctrl-C there ends the command with nothing recorded.
    with start_robot(config, sim) as robot:
        watcher = _install_stop(stop)
        recorder = MoveRecorder(
            robot, freq, names, checkpoint_path=path, replace=force, make_folder=in_library
        )
        recorder.start()  # refused here when another `poppy record` writes the same file
        episode = _start_mcap(robot, mcap, freq, force) if mcap is not None else None
        for motor_name in names:
            robot.motor(motor_name).compliant = True
        for line in start_lines(names, freq, path):
            err_console.print(line, soft_wrap=True, highlight=False, markup=False)
        sys.stderr.flush()
        _wait(recorder, stop, duration)
        stop.set()
        if watcher is not None:
            watcher.wait(1.0)  # a prompt may read stdin next: the watcher must be gone
        try:
            move = recorder.stop()
        except FileError as exc:
            move, save_failure = recorder.move, exc
        mcap_path = _stop_mcap(episode) if episode is not None else None
    if save_failure is not None:
        path = _save_elsewhere(recorder, save_failure, name)
    summary: dict[str, Any] = {
        "path": str(path),
        "frames": len(move),
        "duration_s": round(move.duration_s, 3),
        "framerate": move.framerate,
        "motors": list(move.motors),
    }
    if mcap_path is not None:
        summary["mcap"] = str(mcap_path)
    if json_output:
        print_json(summary)
    else:
        err_console.print(
            f"recorded {len(move)} frames ({move.duration_s:.2f} s) of {len(move.motors)} motors"
        )
        if mcap_path is not None:
            err_console.print(
                f"MCAP for Foxglove: {mcap_path}", soft_wrap=True, highlight=False, markup=False
            )
        sys.stdout.write(f"{printable(str(path))}\n")  # a path may hold terminal escapes
        sys.stdout.flush()
    if save_failure is not None and not _interactive():
        raise typer.Exit(EXIT_FAILURE)
    if mcap is not None and mcap_path is None:
        raise typer.Exit(EXIT_FAILURE)  # the move is saved; the MCAP file, asked for, is not


def start_lines(names: list[str], freq: float, path: Path, width: int = 80) -> list[str]:
    """What a recording's start says, in lines of at most ``width`` columns (a path longer than
    that alone on its line)."""
    listed = ", ".join(names)
    motors = listed if len(listed) <= 30 else f"{len(names)} motors"
    parts = [f"recording {motors} at {freq:g} Hz", f"into {path}"]
    parts.append("— move them by hand; Enter or Ctrl-C stops")
    lines = [parts[0]]
    for part in parts[1:]:
        if len(lines[-1]) + 1 + len(part) <= width:
            lines[-1] += " " + part
        else:
            lines.append(part.removeprefix("— "))
    return lines


def check_mcap(path: Path, force: bool) -> None:
    """The MCAP file can be written (its folder exists, no file there without --force) and
    foxglove-sdk is installed: checked before any motor goes compliant."""
    from poppy_core.files import output_path
    from poppy_core.server.foxglove import McapRecording  # noqa: F401  (the extra, now)

    output_path(path, replace=force)


def _start_mcap(robot: Any, path: Path, freq: float, force: bool) -> McapRecording:
    from poppy_core.server.foxglove import McapRecording

    profile = robot.config.profile if robot.config is not None else None
    name = profile.name if profile is not None else "poppy"
    return McapRecording(robot, path, name, state_rate_hz=freq, replace=force).start()


def _stop_mcap(episode: McapRecording) -> Path | None:
    """Finish the MCAP file; a failure is one line (the move is saved all the same)."""
    from poppy_core.errors import FileError

    try:
        return episode.stop()
    except FileError as exc:
        error_line(f"the MCAP file could not be written: {exc}")
        return None


def check_name(name: str) -> None:
    """A library name for the move's metadata and default file name (not a path)."""
    from poppy_core.motion.move_library import check_name as core_check

    if "/" in name:
        raise typer.BadParameter("with --output, NAME is a name, not a path", param_hint="NAME")
    core_check(name)


def _interactive() -> bool:
    return sys.stdin is not None and sys.stdin.isatty() and err_console.is_terminal


def _save_elsewhere(recorder: MoveRecorder, failure: FileError, name: str) -> Path:
    """Save a take whose destination failed: ask for a place on a terminal, else a temp file.

    Raises:
        FileError: nothing could be written anywhere.
    """
    from poppy_core.errors import FileError

    error_line(f"the take could not be saved: {failure}")
    try:
        while _interactive():
            answer = ask("Save it where? (a file or a folder; empty: a temporary file)")
            if not answer or not answer.strip():
                break
            try:
                return recorder.save(Path(answer.strip()).expanduser())
            except FileError as exc:
                error_line(str(exc))
    except (typer.Abort, SystemExit):  # Ctrl-C, end of input, SIGTERM: the take is the user's
        _save_to_temp(recorder, name)
        raise
    return _save_to_temp(recorder, name)


def _save_to_temp(recorder: MoveRecorder, name: str) -> Path:
    """Save the take to a temporary file, and say where."""
    from poppy_core.errors import FileError
    from poppy_core.motion import fallback_path

    fallback = fallback_path(name)
    try:
        written = recorder.save(fallback)
    except FileError as exc:
        raise FileError(
            f"the take could not be saved to {fallback} either ({exc.args[0]}): it is lost",
            path=str(fallback),
            errno=exc.errno,
        ) from None
    error_line(
        f"the take was saved to {written} instead: `poppy moves import {written}` puts "
        "it in the library"
    )
    return written


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
