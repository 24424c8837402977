"""`poppy calibrate`: record each joint's zero and range into a user profile, or check for drift.

The calibration itself is ``poppy_core.robot.CalibrationSession``; this module renders its
questions with Rich (``RichAnswers``) and writes the result with ``save_user_profile``.
"""

from __future__ import annotations

import os
import sys
import threading
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Any, TextIO, cast

import typer

from poppy_cli.options import ConfigOpt, PortOpt, ProfileOpt, SimOpt, finite, json_option
from poppy_cli.output import (
    EXIT_FAILURE,
    EXIT_USAGE,
    console,
    err_console,
    error_line,
    fmt_deg,
    fmt_value,
    print_json,
    styled,
)
from poppy_cli.prompts import interactive, interruptible, read_key, read_line
from poppy_cli.robots import build_robot

if TYPE_CHECKING:
    from rich.table import Table

    from poppy_core.robot import (
        Calibration,
        CalibrationEvent,
        JointDrift,
        RangeWatch,
        ReferencePosture,
        RobotConfig,
    )

REFRESH_S = 0.1
CANCEL_WORDS = ("q", "quit", "c", "cancel")


class RichAnswers:
    """The session's questions on the terminal: Enter goes on, ``q`` cancels (a single key on a
    terminal; ``q`` then Enter when stdin is a pipe or a file)."""

    def posture(self, posture: ReferencePosture, motors: Sequence[str]) -> bool:
        """Show the posture, wait for Enter."""
        from rich.panel import Panel

        text = posture.description
        if posture.image is not None:
            text += f"\n\npicture: {posture.image}"
        if posture.positions:
            text += "\n\nangles: " + ", ".join(f"{m} {v:g}°" for m, v in posture.positions.items())
        err_console.print(Panel(text, title="reference posture", expand=False))
        return _enter(
            f"Put the robot in this posture ({', '.join(motors)} are free to move), "
            "then press Enter (q to cancel)"
        )

    def move(self, motors: Sequence[str], watch: RangeWatch) -> bool:
        """Show the joints' ranges live until Enter."""
        which = motors[0] if len(motors) == 1 else "each joint"
        answer: list[bool] = []
        done = threading.Event()
        with single_keys() as keys:  # before the prompt: a key typed at once is not lost
            err_console.print(
                styled(
                    "Move [bold]{}[/] slowly from one end of its range to the other, back to the "
                    "posture, then press Enter (q to cancel)",
                    which,
                )
            )
            sys.stderr.flush()

            def read_answer() -> None:
                answer.append(_go_on(keys))
                done.set()

            threading.Thread(target=read_answer, name="calibrate enter", daemon=True).start()
            with interruptible():
                if err_console.is_terminal:
                    from rich.live import Live

                    with Live(_range_table(watch), console=err_console, transient=True) as live:
                        while not done.wait(REFRESH_S):
                            live.update(_range_table(watch))
                else:
                    while not done.wait(REFRESH_S):
                        pass
        for reading in watch.readings():
            low, high = fmt_deg(reading.low), fmt_deg(reading.high)
            err_console.print(f"  {reading.motor}: {low} … {high}")
        return answer[0]

    def confirm(self, question: str) -> bool:
        """A yes/no question (Enter: yes)."""
        from rich.prompt import Confirm

        try:
            with interruptible():
                stream = cast("TextIO", _Lines())  # Rich calls only its readline
                return Confirm.ask(question, default=True, console=err_console, stream=stream)
        except EOFError:  # no more input: the safe answer
            err_console.print()
            return False


class _Lines:
    """stdin for Rich's prompts, read as ``poppy_cli.prompts`` reads it (a signal's handler runs
    at once); the end of input raises EOFError, and the line comes without its newline, as
    ``input()`` gives them (Rich takes a stream's line as it is: "\n" would not be Enter's
    default but an answer it asks again for)."""

    def readline(self) -> str:
        line = read_line() if interactive() else sys.stdin.readline()
        if not line:
            raise EOFError
        return line.rstrip("\r\n")


@contextmanager
def single_keys() -> Iterator[int | None]:
    """On a terminal stdin, its descriptor in cbreak mode (a key is read without Enter, not
    echoed; Ctrl-C still interrupts), the terminal restored on the way out; else None."""
    try:
        fd = sys.stdin.fileno()
    except (AttributeError, OSError, ValueError):  # replaced by a StringIO (tests), closed
        fd = -1
    if fd < 0 or not os.isatty(fd):
        yield None
        return
    import termios
    import tty

    saved = termios.tcgetattr(fd)
    tty.setcbreak(fd, termios.TCSANOW)  # keys typed already are kept (TCSAFLUSH drops them)
    try:
        yield fd
    finally:
        termios.tcsetattr(fd, termios.TCSADRAIN, saved)


def _read_key(fd: int) -> bool:
    """Wait for Enter (True) or q, Esc, Ctrl-D (False) on a terminal in cbreak mode; other keys
    are ignored."""
    while True:
        try:
            key = read_key(fd)
        except OSError:
            return False
        if key in (b"\r", b"\n"):
            return True
        if not key or key.lower() in (b"q", b"c") or key in (b"\x1b", b"\x04"):
            return False


def _go_on(keys: int | None) -> bool:
    """The answer to "press Enter (q to cancel)": a key on a terminal, else a line."""
    if keys is not None:
        return _read_key(keys)
    return _read_line().strip().lower() not in CANCEL_WORDS


def _read_line() -> str:
    try:
        line = sys.stdin.readline()
    except (OSError, ValueError):
        return "q"
    return line if line else "q"  # end of input: cancel rather than wait forever


def _enter(prompt: str) -> bool:
    with single_keys() as keys, interruptible():  # a key typed at once is not lost
        err_console.print(prompt)
        sys.stderr.flush()
        return _go_on(keys)


def _range_table(watch: RangeWatch) -> Table:
    from rich.table import Table

    table = Table(title="ranges so far (degrees, with the new zero)")
    for column in ("joint", "now", "min", "max", "span"):
        table.add_column(column, justify="left" if column == "joint" else "right")
    for r in watch.readings():
        table.add_row(r.motor, f"{r.current:.1f}", f"{r.low:.1f}", f"{r.high:.1f}", f"{r.span:.1f}")
    return table


def _show_event(event: CalibrationEvent) -> None:
    if event.step == "joints" and event.total > 1:
        err_console.print(styled("[bold]joint {}/{}[/]", event.index, event.total))
    elif event.step == "compliant":
        err_console.print(event.message)


def _motor_list(text: str | None) -> list[str] | None:
    if text is None:
        return None
    names = [part.strip() for part in text.split(",") if part.strip()]
    if not names:
        raise typer.BadParameter("no motor given; e.g. --motors m1,m2 or --motors base")
    return names


def calibrate(
    profile: str | None = ProfileOpt,
    config_file: Path | None = ConfigOpt,
    port: str | None = PortOpt,
    sim: str | None = SimOpt,
    motors: str | None = typer.Option(
        None, "--motors", "-m", help="Joints or groups to calibrate, e.g. m1,m2 or base (all)."
    ),
    name: str | None = typer.Option(
        None, "--name", "-n", help="User profile to write (default: the robot's profile name)."
    ),
    all_at_once: bool = typer.Option(
        False, "--all-at-once", help="Move every joint through its range in one go."
    ),
    check: bool = typer.Option(
        False, "--check", help="Compare the robot to its calibration and report drift."
    ),
    tolerance: float = typer.Option(
        3.0,
        "--tolerance",
        min=0.0,
        max=360.0,
        callback=finite,
        help="--check: drift allowed, in degrees.",
    ),
    yes: bool = typer.Option(False, "--yes", "-y", help="Write the profile without asking."),
    json_output: bool = json_option("Print the result as JSON."),
) -> None:
    """Calibrate a robot: each joint's zero (in its reference posture) and reachable range.

    The joints turn compliant; put the robot in the posture shown, press Enter, then move each
    joint through its range. The result goes to a user profile (the previous file is kept as
    profile.yaml.bak) that --profile NAME then uses. Ctrl-C or q leaves the previous calibration
    untouched. --check reads the robot in its posture and reports how far each joint drifted.
    """
    from poppy_cli.robots import robot_config
    from poppy_core.robot import CalibrationSession, check_calibration
    from poppy_core.robot.calibration import check_motors
    from poppy_core.robot.profile_store import check_profile_name

    chosen = _motor_list(motors)
    # Bad input is refused before the robot is built (nothing moves, nothing turns compliant).
    config = robot_config(profile, config_file, port)
    joints = check_motors(config, chosen)
    target = name or (config.profile.name if config.profile is not None else None)
    if not check:
        if not target:
            error_line("this config has no profile name: pass --name NAME for the user profile")
            raise typer.Exit(EXIT_USAGE)
        check_profile_name(target)
    with build_robot(profile, config_file, port, sim) as robot:
        assert robot.config is not None
        config = robot.config
        if check:
            drifts = check_calibration(robot, RichAnswers(), joints, tolerance_deg=tolerance)
            _report_check(config, drifts, json_output)
            return
        assert target is not None
        session = CalibrationSession(
            robot, RichAnswers(), joints, one_at_a_time=not all_at_once, on_event=_show_event
        )
        calibration = session.run()
    _save(config, calibration, target, yes=yes, json_output=json_output)


def _save(
    config: RobotConfig, calibration: Calibration, name: str, *, yes: bool, json_output: bool
) -> None:
    from poppy_core.robot.profile_store import save_calibration, user_profile_path

    changes = calibration.changes(config)
    if not json_output:
        err_console.print(_changes_table(changes))
    path = user_profile_path(name)
    if not yes and not RichAnswers().confirm(f"Write the calibration to {path}?"):
        err_console.print("nothing written")
        raise typer.Exit(EXIT_FAILURE)
    saved = save_calibration(config, calibration, name, by="poppy calibrate")
    summary = {
        "profile": name,
        "path": str(saved.path),
        "backup": str(saved.backup) if saved.backup else None,
        "calibrated": calibration.created,
        "joints": [
            {"name": m, "offset": c["offset"][1], "angle_limit": list(c["angle_limit"][1])}
            for m, c in changes.items()
        ],
    }
    if json_output:
        print_json(summary)
        return
    kept = f" (the previous file is kept as {saved.backup.name})" if saved.backup else ""
    console.print(f"wrote {saved.path}{kept}; --profile {name} now uses this calibration")


def _changes_table(changes: dict[str, dict[str, Any]]) -> Table:
    from rich.table import Table

    table = Table(title="calibration (degrees)")
    for column in ("joint", "offset", "new offset", "limits", "new limits"):
        table.add_column(column, justify="left" if column == "joint" else "right")
    for motor, change in changes.items():
        (old_offset, new_offset), (old_limit, new_limit) = change["offset"], change["angle_limit"]
        table.add_row(
            motor,
            fmt_value(old_offset),
            fmt_value(new_offset),
            f"{fmt_value(old_limit[0])} … {fmt_value(old_limit[1])}",
            f"{fmt_value(new_limit[0])} … {fmt_value(new_limit[1])}"
            + ("" if change["range_recorded"] else " (kept)"),
        )
    return table


def _deg(value: float, sign: str = "") -> str:
    """``1.2°`` (never ``-0.0°``)."""
    return f"{round(value, 1) + 0.0:{sign}.1f}°"


def _report_check(config: RobotConfig, drifts: list[JointDrift], json_output: bool) -> None:
    from rich.table import Table

    from poppy_core.robot.calibration import calibrated_on

    when = calibrated_on(config)
    drifted = [d.motor for d in drifts if not d.ok]
    if json_output:
        print_json(
            {
                "calibrated": when,
                "tolerance_deg": drifts[0].tolerance if drifts else None,
                "joints": [
                    {
                        "name": d.motor,
                        "expected": d.expected,
                        "measured": round(d.measured, 2),
                        "drift": round(d.drift, 2),
                        "ok": d.ok,
                    }
                    for d in drifts
                ],
                "drifted": drifted,
            }
        )
    else:
        title = f"calibrated {when}" if when else "not calibrated: profile zeros"
        table = Table(title=f"drift in the reference posture ({title})")
        for column in ("joint", "expected", "measured", "drift", ""):
            table.add_column(column, justify="left" if column in ("joint", "") else "right")
        for d in drifts:
            mark = styled("[green]ok[/]") if d.ok else styled("[red]drifted[/]")
            table.add_row(d.motor, _deg(d.expected), _deg(d.measured), _deg(d.drift, "+"), mark)
        console.print(table)
        if drifted:
            console.print(
                f"{', '.join(drifted)} drifted more than {drifts[0].tolerance:g}°: "
                "run `poppy calibrate` again"
            )
    if drifted:
        raise typer.Exit(EXIT_FAILURE)
