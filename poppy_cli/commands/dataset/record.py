"""`poppy dataset record`: the options checked (every refusal before a robot is built: one
line, exit 2), then ``recording.record_episodes``."""

from __future__ import annotations

import sys
from pathlib import Path

import typer

from poppy_cli import complete
from poppy_cli.commands.dataset.checks import (
    camera_specs,
    core,
    episode_count,
    seconds,
    source_of,
    usage,
)
from poppy_cli.commands.dataset.recording import Plan, config_cameras, record_episodes
from poppy_cli.commands.dataset.sources import ZENOH, load_move
from poppy_cli.options import ConfigOpt, JsonSummaryOpt, PortOpt, ProfileOpt, SimOpt
from poppy_cli.output import console, print_json, printable


def record(
    repo_id: str = typer.Argument(..., help="The dataset's name, user/name (as on LeRobot's hub)."),
    root: Path | None = typer.Option(
        None, "--root", help="Its folder. [default: $HF_LEROBOT_HOME/REPO_ID, as LeRobot's]"
    ),
    resume: bool = typer.Option(False, "--resume", help="Add episodes to the dataset in --root."),
    play: str | None = typer.Option(
        None, "--play", help="Actions: play this move each episode.", autocompletion=complete.moves
    ),
    primitive: str | None = typer.Option(None, "--primitive", help="Actions: run this primitive."),
    by_hand: bool = typer.Option(
        False,
        "--by-hand",
        help="Actions: the robot compliant, moved by hand (action = next state).",
    ),
    leader: str | None = typer.Option(
        None,
        "--leader",
        help="Actions: a leader arm's positions (a profile, a config file, or zenoh:NAME: "
        "a robot served with `poppy serve --zenoh`).",
        autocompletion=complete.profiles,
    ),
    leader_port: str | None = typer.Option(
        None,
        "--leader-port",
        help="Serial port of the leader's bus.",
        autocompletion=complete.ports,
    ),
    connect: list[str] | None = typer.Option(
        None,
        "--zenoh-connect",
        "--connect",
        help="For a zenoh:NAME leader: a Zenoh peer or router to connect to (repeat it). "
        "Default: POPPY_ZENOH_CONNECT, else tcp/127.0.0.1:7447.",
    ),
    episodes: int = typer.Option(1, "--episodes", help="Episodes to record (1 to 10000)."),
    episode_s: float = typer.Option(20.0, "--episode-s", help="Length of an episode in s."),
    reset_s: float = typer.Option(5.0, "--reset-s", help="Pause between episodes in s."),
    task: str = typer.Option(..., "--task", help="What is done, in words (one line)."),
    fps: int = typer.Option(30, "--fps", help="Frames per second (1 to 240)."),
    camera: list[str] | None = typer.Option(
        None,
        "--camera",
        help="NAME (a camera of the robot) or NAME=SPEC (dummy[:WxH], an "
        "index, a device, a video file); repeat it. [default: the robot's cameras]",
    ),
    no_cameras: bool = typer.Option(False, "--no-cameras", help="Record no camera."),
    profile: str | None = ProfileOpt,
    config_file: Path | None = ConfigOpt,
    port: str | None = PortOpt,
    sim: str | None = SimOpt,
    json_output: bool = JsonSummaryOpt,
) -> None:
    """Record episodes into a LeRobot dataset (v3.0): state, action, camera videos, a task.

    Each episode lasts --episode-s, then --reset-s to put things back. On a terminal, the keys
    of lerobot-record: right arrow ends the episode (or the reset), left arrow records it
    again, Esc (or Enter, Ctrl-C) stops: the episode under way is saved. Every saved episode
    stays in the dataset, even if the recording is killed. Train on it with
    `lerobot-train --dataset.root DIR`.
    """
    from poppy_core.dataset import layout
    from poppy_core.dataset.writer import default_root

    core(lambda: layout.check_repo_id(repo_id), "REPO_ID")
    core(lambda: layout.check_fps(fps), "--fps")
    core(lambda: layout.check_task(task), "--task")
    episode_count(episodes)
    seconds(episode_s, "--episode-s", 0.1)
    seconds(reset_s, "--reset-s", 0.0)
    source = source_of(play, primitive, by_hand, leader)
    if leader_port is not None and (leader is None or leader.startswith(ZENOH)):
        raise usage("--leader-port goes with --leader PROFILE", "--leader-port")
    if connect and (leader is None or not leader.startswith(ZENOH)):
        raise usage("--zenoh-connect goes with --leader zenoh:NAME", "--zenoh-connect")
    cameras = camera_specs(camera or [])
    if no_cameras and cameras:
        raise usage("--no-cameras records none: leave out --camera", "--no-cameras")
    folder = Path(root).expanduser() if root is not None else default_root(repo_id)
    if folder.exists() and not resume:
        raise usage(
            f"{folder} already exists: pass --resume to add episodes, or choose another --root",
            "--root",
        )
    if resume and not (folder / layout.INFO_PATH).is_file():
        raise usage(f"{folder} holds no dataset to resume (no {layout.INFO_PATH})", "--resume")
    from poppy_cli.robots import robot_config
    from poppy_core.extras import require

    require("pyarrow", "av", extra="dataset")
    config = robot_config(profile, config_file, port)
    move = load_move(play, config) if play is not None else None
    profile_cameras = config_cameras(config)
    for name, spec in cameras.items():
        if spec is None and name not in profile_cameras:
            raise usage(
                f"no camera {name!r} on this robot "
                f"(cameras: {', '.join(profile_cameras) or 'none'}): give NAME=SPEC for another",
                "--camera",
            )
    use_robot_cameras = not no_cameras and (not cameras or any(s is None for s in cameras.values()))
    plan = Plan(
        repo_id,
        folder,
        resume,
        source,
        move,
        primitive,
        leader,
        leader_port,
        connect,
        cameras,
        use_robot_cameras,
        no_cameras,
        episodes,
        episode_s,
        reset_s,
        task,
        fps,
        show=not json_output,
    )
    summary = record_episodes(config, sim, plan)
    if json_output:
        print_json(summary)
    else:
        console.print(
            f"recorded {len(summary['saved'])} episode(s), {summary['frames']} frames, "
            f"{summary['dropped']} dropped; the dataset holds {summary['total_episodes']} episodes"
        )
        sys.stdout.write(f"{printable(str(folder))}\n")
        sys.stdout.flush()
