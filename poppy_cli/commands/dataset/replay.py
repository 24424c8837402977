"""`poppy dataset replay`: play an episode's actions on a robot.

Every refusal (no such episode, a bad speed, joints the robot lacks) comes before a robot is
built: one line, exit 2. The replay is ``poppy play``'s player on a move made of the episode's
frames (a ramp to the first frame, then the frames at the dataset's fps times --speed).
"""

from __future__ import annotations

import signal
import threading
from pathlib import Path

import typer

from poppy_cli.commands.dataset.checks import EpisodeOpt, RootOpt, core, dataset_folder
from poppy_cli.options import ConfigOpt, JsonSummaryOpt, PortOpt, ProfileOpt, SimOpt, finite
from poppy_cli.output import EXIT_INTERRUPTED, console, err_console, print_json, printable


def replay(
    repo_id: str = typer.Argument(..., help="The dataset's name, user/name."),
    root: Path | None = RootOpt,
    episode: int = EpisodeOpt,
    speed: float = typer.Option(
        1.0, "--speed", "-s", min=0.01, max=100.0, callback=finite, help="2 = twice as fast."
    ),
    profile: str | None = ProfileOpt,
    config_file: Path | None = ConfigOpt,
    port: str | None = PortOpt,
    sim: str | None = SimOpt,
    json_output: bool = JsonSummaryOpt,
) -> None:
    """Play an episode's actions on a robot: a ramp to its first frame, then every frame.

    The motors turn stiff. Ctrl-C or SIGTERM stops where the motors are (exit 130, after the
    summary). The dataset's joints must be motors of the robot.
    """
    from poppy_cli.commands.play import _run, warn_clamped
    from poppy_cli.robots import robot_config, start_robot
    from poppy_core.dataset.rows import read_actions
    from poppy_core.motion import Move, MovePlayer

    folder = dataset_folder(repo_id, root)
    actions = core(lambda: read_actions(folder, episode), "--episode")
    config = robot_config(profile, config_file, port)
    missing = [m for m in actions.motors if m not in config.motors]
    if missing:
        raise typer.BadParameter(
            f"the dataset's joints {', '.join(missing)} are not motors of this robot "
            f"({', '.join(config.motors)}): replay it on the robot it was recorded with",
            param_hint="--profile",
        )
    move = core(
        lambda: Move(actions.fps, actions.motors, actions.positions, metadata={"episode": episode}),
        "--episode",
    )
    with start_robot(config, sim) as robot:
        player = MovePlayer(robot, move, speed=speed)
        warn_clamped(player, robot, "the episode")
        stop = threading.Event()
        for signum in (signal.SIGINT, signal.SIGTERM):
            signal.signal(signum, lambda *_: stop.set())
        err_console.print(
            f"replaying episode {episode} of {printable(str(folder))}: Ctrl-C stops it",
            soft_wrap=True,
            highlight=False,
            markup=False,
        )
        _run(player, stop, show=not json_output)
    summary = {
        "root": str(folder),
        "episode": episode,
        "frames": len(move),
        "motors": list(move.motors),
        "speed": speed,
        "duration_s": round(player.duration_s, 3),
        "played_s": round(player.played_s, 3),
        "completed": not player.stopped,
    }
    if json_output:
        print_json(summary)
    else:
        state = "replayed" if not player.stopped else "stopped after"
        console.print(
            f"{state} {player.played_s:.2f} s of episode {episode} ({len(move)} frames)",
            highlight=False,
        )
    if stop.is_set():
        raise typer.Exit(EXIT_INTERRUPTED)
