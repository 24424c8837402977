"""`poppy play NAME|PATH`: play a recorded move (ours or pypot's JSON) on a robot."""

from __future__ import annotations

import signal
import threading
from pathlib import Path
from typing import TYPE_CHECKING

import typer

from poppy_cli import complete
from poppy_cli.options import (
    ConfigOpt,
    JsonSummaryOpt,
    PortOpt,
    ProfileOpt,
    RemoteOpt,
    SimOpt,
    finite,
)
from poppy_cli.output import (
    EXIT_INTERRUPTED,
    console,
    err_console,
    print_json,
    styled,
    warn_line,
)
from poppy_cli.robots import robot_config, start_robot

if TYPE_CHECKING:
    from poppy_core.motion import MovePlayer, PlayProgress
    from poppy_core.robot import Robot


def play(
    name: str = typer.Argument(
        ..., help="Library name of the move, or a file path.", autocompletion=complete.moves
    ),
    speed: float = typer.Option(
        1.0, "--speed", "-s", min=0.01, max=100.0, callback=finite, help="2 = twice as fast."
    ),
    reverse: bool = typer.Option(False, "--reverse", "-r", help="Play it backwards."),
    loop: int = typer.Option(1, "--loop", "-l", min=1, max=10_000, help="Play it this many times."),
    profile: str | None = ProfileOpt,
    config_file: Path | None = ConfigOpt,
    port: str | None = PortOpt,
    sim: str | None = SimOpt,
    json_output: bool = JsonSummaryOpt,
    remote: str | None = RemoteOpt,
) -> None:
    """Play a move: a gentle ramp to its first frame, then the frames at the chosen speed.

    The motors of the move turn stiff. Ctrl-C or SIGTERM stops where the motors are (exit 130,
    after the summary). With --remote, NAME is a move of the server's library.
    """
    if remote:
        from poppy_cli.commands.remote_runs import play_remote

        play_remote(remote, name, speed, reverse, loop, json_output)
        return
    from poppy_core.errors import ConfigError
    from poppy_core.motion import MovePlayer, load_move, move_path

    path = move_path(name)
    move = load_move(path)
    config = robot_config(profile, config_file, port)
    missing = [m for m in move.motors if m not in config.motors]
    if missing:  # refused before the robot is built; MovePlayer says the same
        raise ConfigError(
            f"the robot lacks the move's motor{'s' if len(missing) > 1 else ''} "
            f"{', '.join(missing)} (robot motors: {', '.join(config.motors)})",
            field="motors",
            value=missing,
        )
    with start_robot(config, sim) as robot:
        player = MovePlayer(robot, move, speed=speed, backwards=reverse, loops=loop)
        warn_clamped(player, robot, "the move")
        stop = threading.Event()
        for signum in (signal.SIGINT, signal.SIGTERM):
            signal.signal(signum, lambda *_: stop.set())
        err_console.print(styled("playing {}: Ctrl-C stops it", path.name), soft_wrap=True)
        _run(player, stop, show=not json_output)
    summary = {
        "path": str(path),
        "motors": list(move.motors),
        "speed": speed,
        "reverse": reverse,
        "loops": loop,
        "duration_s": round(player.duration_s, 3),
        "played_s": round(player.played_s, 3),
        "completed": not player.stopped,
    }
    if json_output:
        print_json(summary)
    else:
        state = "played" if not player.stopped else "stopped after"
        console.print(f"{state} {player.played_s:.2f} s of {path.name} ({', '.join(move.motors)})")
    if stop.is_set():  # a signal ended it: an interruption, as everywhere in the CLI
        raise typer.Exit(EXIT_INTERRUPTED)


def fmt_limits(limits: tuple[float, float]) -> str:
    """``[-90, 90]``."""
    return f"[{limits[0]:g}, {limits[1]:g}]"


def _run(player: MovePlayer, stop: threading.Event, *, show: bool) -> None:
    if not show:
        player.start()
        while not player.wait(0.1):
            if stop.is_set():
                player.stop()
        _raise_error(player)
        return
    from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

    columns = (
        TextColumn("{task.description}", markup=False),
        BarColumn(),
        TextColumn("{task.percentage:>3.0f}%"),
        TimeRemainingColumn(),
    )
    with Progress(*columns, console=err_console, transient=True) as progress:
        task = progress.add_task("going to the first frame", total=1.0)

        def update(event: PlayProgress) -> None:
            label = "going to the first frame" if event.phase == "ramp" else "playing"
            if player.loops > 1:
                label += f" (loop {event.loop}/{event.loops})"
            progress.update(task, completed=event.fraction, description=label)

        player.on_progress = update
        player.start()
        while not player.wait(0.1):
            if stop.is_set():
                player.stop()
    _raise_error(player)


def _raise_error(player: MovePlayer) -> None:
    if player.error is not None:
        raise player.error


def warn_clamped(player: MovePlayer, robot: Robot, what: str) -> None:
    """One line per motor that ``what`` (the move, the episode) takes past its angle limits."""
    for motor, beyond in player.clamped.items():
        warn_line(
            f"{motor}: {what} goes {beyond:.1f}° past its angle limits "
            f"{fmt_limits(robot.motor(motor).angle_limit)}: played at the limit"
        )
