"""`poppy dataset record|info|list|replay|delete-episode`: LeRobot datasets (v3.0) from a robot.

The format is ``poppy_core.dataset``; the recording loop ``poppy_core.motion.episodes``. This
module checks the options (every refusal before a robot is built: one line, exit 2), builds
the robot, its cameras and the source of actions, and shows a live line.
"""

from __future__ import annotations

import math
import sys
import threading
from contextlib import ExitStack
from pathlib import Path
from typing import TYPE_CHECKING, Any

import typer

from poppy_cli import complete
from poppy_cli.commands import dataset_edit
from poppy_cli.options import ConfigOpt, JsonOpt, JsonSummaryOpt, PortOpt, ProfileOpt, SimOpt
from poppy_cli.output import console, err_console, print_json, printable

if TYPE_CHECKING:
    from poppy_core.dataset.layout import DatasetSpec
    from poppy_core.motion.episodes import ActionSource, Progress
    from poppy_core.robot import Robot, RobotConfig

app = typer.Typer(
    help="LeRobot datasets (v3.0): record episodes from a robot, look at them.",
    no_args_is_help=True,
)
MAX_EPISODE_S = 3600.0
LIVE_EVERY_S = 0.25


def _usage(message: str, hint: str | None = None) -> typer.BadParameter:
    return typer.BadParameter(message, param_hint=hint)


def _seconds(value: float, name: str, low: float) -> float:
    if not math.isfinite(value) or not low <= value <= MAX_EPISODE_S:
        raise _usage(f"{value!r}: give {low:g} to {MAX_EPISODE_S:g} seconds", name)
    return value


def _core(call: Any, hint: str) -> Any:
    """A core check; its ArgumentError becomes a usage error (exit 2) on ``hint``."""
    from poppy_core.errors import ArgumentError

    try:
        return call()
    except ArgumentError as exc:
        raise _usage(str(exc), hint) from None


def _camera_specs(specs: list[str]) -> dict[str, str | None]:
    """``NAME`` (a camera of the robot's config) or ``NAME=SPEC`` (dummy[:WxH], an index, a
    device or a video file), in order."""
    from poppy_core.dataset.layout import NAME

    found: dict[str, str | None] = {}
    for text in specs:
        name, has_spec, spec = text.partition("=")
        if not NAME.fullmatch(name) or (has_spec and not spec):
            raise _usage(
                f"{text!r}: give NAME or NAME=SPEC (dummy, dummy:640x480, 0, /dev/video0)",
                "--camera",
            )
        found[name] = spec if has_spec else None
    return found


def _source_of(play: str | None, primitive: str | None, by_hand: bool, leader: str | None) -> str:
    chosen = [
        flag
        for flag, given in (
            ("--play", play is not None),
            ("--primitive", primitive is not None),
            ("--by-hand", by_hand),
            ("--leader", leader is not None),
        )
        if given
    ]
    if len(chosen) != 1:
        raise _usage(
            "give one source of actions: --play MOVE, --primitive NAME, --by-hand or "
            f"--leader PROFILE (got {', '.join(chosen) or 'none'})"
        )
    return chosen[0]


@app.command("record")
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
        help="Actions: a leader arm's positions (a profile or config file).",
        autocompletion=complete.profiles,
    ),
    leader_port: str | None = typer.Option(
        None,
        "--leader-port",
        help="Serial port of the leader's bus.",
        autocompletion=complete.ports,
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

    Each episode lasts --episode-s (Enter or Ctrl-C ends the recording: the episode under way
    is saved), then --reset-s to put things back. Every saved episode stays in the dataset,
    even if the recording is killed. Train on it with `lerobot-train --dataset.root DIR`.
    """
    from poppy_core.dataset import layout
    from poppy_core.dataset.writer import default_root

    _core(lambda: layout.check_repo_id(repo_id), "REPO_ID")
    _core(lambda: layout.check_fps(fps), "--fps")
    _core(lambda: layout.check_task(task), "--task")
    if not 1 <= episodes <= 10_000:
        raise _usage(f"{episodes}: give 1 to 10000 episodes", "--episodes")
    _seconds(episode_s, "--episode-s", 0.1)
    _seconds(reset_s, "--reset-s", 0.0)
    source = _source_of(play, primitive, by_hand, leader)
    if leader_port is not None and leader is None:
        raise _usage("--leader-port goes with --leader PROFILE", "--leader-port")
    cameras = _camera_specs(camera or [])
    if no_cameras and cameras:
        raise _usage("--no-cameras records none: leave out --camera", "--no-cameras")
    folder = Path(root).expanduser() if root is not None else default_root(repo_id)
    if folder.exists() and not resume:
        raise _usage(
            f"{folder} already exists: pass --resume to add episodes, or choose another --root",
            "--root",
        )
    if resume and not (folder / layout.INFO_PATH).is_file():
        raise _usage(f"{folder} holds no dataset to resume (no {layout.INFO_PATH})", "--resume")
    from poppy_cli.robots import robot_config
    from poppy_core.extras import require

    require("pyarrow", "av", extra="dataset")
    config = robot_config(profile, config_file, port)
    move = _load_move(play, config) if play is not None else None
    profile_cameras = _config_cameras(config)
    for name, spec in cameras.items():
        if spec is None and name not in profile_cameras:
            raise _usage(
                f"no camera {name!r} on this robot "
                f"(cameras: {', '.join(profile_cameras) or 'none'}): give NAME=SPEC for another",
                "--camera",
            )
    use_robot_cameras = not no_cameras and (not cameras or any(s is None for s in cameras.values()))
    summary = _record(
        config,
        sim,
        folder,
        repo_id,
        resume,
        source,
        move,
        primitive,
        leader,
        leader_port,
        cameras,
        use_robot_cameras,
        no_cameras,
        episodes,
        episode_s,
        reset_s,
        task,
        fps,
        json_output,
    )
    if json_output:
        print_json(summary)
    else:
        console.print(
            f"recorded {len(summary['saved'])} episode(s), {summary['frames']} frames, "
            f"{summary['dropped']} dropped; the dataset holds {summary['total_episodes']} episodes"
        )
        sys.stdout.write(f"{printable(str(folder))}\n")
        sys.stdout.flush()


def _load_move(name: str, config: RobotConfig) -> Any:
    from poppy_core.errors import ConfigError
    from poppy_core.motion import load_move, move_path

    move = load_move(move_path(name))
    missing = [m for m in move.motors if m not in config.motors]
    if missing:
        raise ConfigError(f"the robot lacks the move's motors {', '.join(missing)}", field="motors")
    return move


def _config_cameras(config: RobotConfig) -> list[str]:
    data = config.to_dict()
    return [
        name
        for name, spec in (data.get("sensors") or {}).items()
        if str(spec.get("type", "")).endswith("Camera")
    ]


def _make_camera(name: str, spec: str) -> Any:
    from poppy_core.sensors.camera import DummyCamera

    kind, _, size = spec.partition(":")
    if kind == "dummy":
        width, _, height = (size or "640x480").lower().partition("x")
        if not (width.isdigit() and height.isdigit()):
            raise _usage(f"{spec!r}: give dummy:WIDTHxHEIGHT", "--camera")
        return DummyCamera(name, (int(width), int(height)), 30.0)
    from poppy_core.extras import require

    require("cv2", extra="vision", feature="cameras")
    from poppy_core.sensors.opencv_camera import OpenCVCamera

    return OpenCVCamera(name, int(spec) if spec.isdigit() else spec, 30.0)


def _record(
    config: RobotConfig,
    sim: str | None,
    folder: Path,
    repo_id: str,
    resume: bool,
    source: str,
    move: Any,
    primitive: str | None,
    leader: str | None,
    leader_port: str | None,
    cameras: dict[str, str | None],
    use_robot_cameras: bool,
    no_cameras: bool,
    episodes: int,
    episode_s: float,
    reset_s: float,
    task: str,
    fps: int,
    json_output: bool,
) -> dict[str, Any]:
    from poppy_cli.commands.record import _install_stop
    from poppy_cli.robots import start_robot
    from poppy_core.dataset.layout import DatasetSpec
    from poppy_core.motion.episodes import EpisodeRecorder
    from poppy_core.sensors import Camera

    with ExitStack() as stack:
        robot = stack.enter_context(start_robot(config, sim, sensors=use_robot_cameras))
        chosen: dict[str, Any] = {}
        robot_cameras = {s.name: s for s in robot.sensors if isinstance(s, Camera)}
        if not no_cameras:
            names = [n for n, s in cameras.items() if s is None] or (
                list(robot_cameras) if not cameras else []
            )
            chosen = {name: robot_cameras[name] for name in names}
            for name, spec in cameras.items():
                if spec is not None:
                    made = _make_camera(name, spec)
                    stack.callback(made.close)
                    chosen[name] = made
        motors = list(config.motors)
        sizes = {name: cam.frame.shape[:2] for name, cam in chosen.items()}  # waits for a frame
        spec = _core(
            lambda: DatasetSpec(
                fps,
                tuple(motors),
                {n: (int(h), int(w)) for n, (h, w) in sizes.items()},
                config.profile.name if config.profile is not None else None,
            ),
            "--camera",
        )
        writer = _open_writer(folder, spec, resume)
        stack.callback(writer.close)
        actions = _action_source(stack, robot, motors, source, move, primitive, leader, leader_port)
        recorder = EpisodeRecorder(robot, writer, motors, chosen, actions)
        stop = threading.Event()
        _install_stop(stop)
        err_console.print(
            f"recording {episodes} episode(s) of {episode_s:g} s at {fps} fps into {folder} "
            f"(cameras: {', '.join(chosen) or 'none'}) — Enter or Ctrl-C stops",
            soft_wrap=True,
            highlight=False,
            markup=False,
        )
        saved, dropped = [], 0
        live = _Live(episodes, episode_s, show=not json_output)
        for number in range(episodes):
            if stop.is_set():
                break
            episode = recorder.record(
                task, episode_s, episode=number, stop=stop, on_tick=live.update
            )
            if episode is not None:
                saved.append(episode)
                dropped += live.dropped
                live.done(episode)
            if number + 1 < episodes and reset_s > 0 and not stop.is_set():
                live.reset(number, reset_s)
                stop.wait(reset_s)
    return {
        "root": str(folder),
        "repo_id": repo_id,
        "saved": [
            {"episode": e.index, "frames": e.frames, "duration_s": round(e.duration_s, 3)}
            for e in saved
        ],
        "frames": sum(e.frames for e in saved),
        "dropped": dropped,
        "total_episodes": len(writer.episodes),
    }


def _open_writer(folder: Path, spec: DatasetSpec, resume: bool) -> Any:
    from poppy_core.dataset.writer import DatasetWriter

    if resume:
        return _core(lambda: DatasetWriter.resume(folder, spec), "--resume")
    return _core(lambda: DatasetWriter.create(folder, spec), "--root")


def _action_source(
    stack: ExitStack,
    robot: Robot,
    motors: list[str],
    source: str,
    move: Any,
    primitive: str | None,
    leader: str | None,
    leader_port: str | None,
) -> ActionSource:
    from poppy_core.motion import episodes

    if source == "--by-hand":
        return episodes.ByHand(robot, motors)
    if source == "--play":
        from poppy_core.motion import MovePlayer

        players: list[Any] = []

        def start_move() -> None:
            players.append(MovePlayer(robot, move))
            players[-1].start()

        def stop_move() -> None:
            if players:
                players.pop().stop()

        return episodes.Goals(robot, motors, start_move, stop_move)
    if source == "--primitive":
        from poppy_cli.commands.primitive import _find, robot_primitives

        _, found = _core(lambda: _find(robot_primitives(robot), str(primitive)), "--primitive")
        return episodes.Goals(robot, motors, found.start, found.stop)
    from poppy_cli.commands.teleop import _build, _config
    from poppy_core.motion.teleop.session import Teleoperation

    lead = stack.enter_context(_build(_config(str(leader), leader_port, "leader"), None))
    missing = [m for m in motors if m not in [x.name for x in lead.motors]]
    if missing:
        raise _usage(
            f"the leader lacks {', '.join(missing)}: a leader of the same kind", "--leader"
        )
    runs: list[Any] = []

    def start_teleop() -> None:
        runs.append(Teleoperation(lead, robot))
        runs[-1].start()

    def stop_teleop() -> None:
        if runs:
            runs.pop().stop()

    return episodes.Teleoperated(lead, motors, start_teleop, stop_teleop)


class _Live:
    """The live line on stderr (a terminal), a line per episode elsewhere."""

    def __init__(self, episodes: int, episode_s: float, *, show: bool) -> None:
        self.episodes, self.episode_s, self.show = episodes, episode_s, show
        self.dropped = 0
        self._last = -1.0
        self._terminal = show and err_console.is_terminal

    def update(self, progress: Progress) -> None:
        self.dropped = progress.dropped
        if not self._terminal or progress.elapsed_s - self._last < LIVE_EVERY_S:
            return
        self._last = progress.elapsed_s
        sys.stderr.write(
            f"\r episode {progress.episode + 1}/{self.episodes}  {progress.elapsed_s:5.1f}/"
            f"{self.episode_s:g} s  {progress.frames} frames  {progress.dropped} dropped   "
        )
        sys.stderr.flush()

    def done(self, episode: Any) -> None:
        self._last = -1.0
        if self.show:
            end = "\n" if self._terminal else ""
            err_console.print(
                f"{end}episode {episode.index} saved: {episode.frames} frames "
                f"({episode.duration_s:.1f} s), {self.dropped} dropped",
                highlight=False,
            )

    def reset(self, number: int, reset_s: float) -> None:
        if self.show:
            err_console.print(f"reset: {reset_s:g} s before episode {number + 2}", highlight=False)


@app.command("info")
def info(
    root: Path = typer.Argument(..., help="The dataset's folder."),
    json_output: bool = JsonOpt,
) -> None:
    """What a dataset holds: episodes, frames, duration, tasks, cameras, joints."""
    summary = _summary(root)
    if json_output:
        print_json(summary.as_json())
        return
    console.print(
        f"{printable(str(summary.root))}: LeRobot {summary.codebase_version}, "
        f"{len(summary.episodes)} episodes, {summary.frames} frames, "
        f"{summary.duration_s:.1f} s at {summary.fps} fps",
        highlight=False,
    )
    console.print(
        f"robot: {summary.robot_type or '-'}; joints: {', '.join(summary.joints)}", highlight=False
    )
    console.print(f"cameras: {', '.join(summary.cameras) or 'none'}", highlight=False)
    for index, text in enumerate(summary.tasks):
        console.print(f"task {index}: {printable(text)}", highlight=False)


@app.command("list")
def list_episodes(
    root: Path = typer.Argument(..., help="The dataset's folder."),
    json_output: bool = JsonOpt,
) -> None:
    """The episodes of a dataset: frames, duration, task."""
    summary = _summary(root)
    rows = [
        {
            "episode": e.index,
            "frames": e.frames,
            "duration_s": round(e.duration_s, 3),
            "tasks": list(e.tasks),
        }
        for e in summary.episodes
    ]
    if json_output:
        print_json(rows)
        return
    from rich.table import Table

    table = Table(title=f"{len(rows)} episodes at {summary.fps} fps")
    for column in ("episode", "frames", "duration", "task"):
        table.add_column(column, justify="left" if column == "task" else "right")
    for row in rows:
        table.add_row(
            str(row["episode"]),
            str(row["frames"]),
            f"{row['duration_s']:.2f} s",
            printable(", ".join(row["tasks"])),
        )
    console.print(table)


def _summary(root: Path) -> Any:
    from poppy_core.extras import require

    require("pyarrow", extra="dataset")
    from poppy_core.dataset.reader import read_summary

    return read_summary(root)


app.command("replay")(dataset_edit.replay)
app.command("delete-episode")(dataset_edit.delete_episode)
