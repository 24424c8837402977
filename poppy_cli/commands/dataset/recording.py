"""A recording: the robot, its cameras, the writer and the source of actions, then the episodes."""

from __future__ import annotations

from contextlib import ExitStack
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from poppy_cli.commands.dataset.checks import core, usage
from poppy_cli.commands.dataset.sources import action_source, open_leader
from poppy_cli.output import err_console

if TYPE_CHECKING:
    from poppy_cli.commands.dataset.live import Keys, Live
    from poppy_core.dataset.layout import DatasetSpec
    from poppy_core.robot import RobotConfig


@dataclass
class Plan:
    """What `poppy dataset record` was asked, checked."""

    repo_id: str
    folder: Path
    resume: bool
    source: str
    move: Any
    primitive: str | None
    leader: str | None
    leader_port: str | None
    connect: list[str] | None
    cameras: dict[str, str | None]
    use_robot_cameras: bool
    no_cameras: bool
    episodes: int
    episode_s: float
    reset_s: float
    task: str
    fps: int
    show: bool


def config_cameras(config: RobotConfig) -> list[str]:
    """The cameras of a robot's config, by name."""
    data = config.to_dict()
    return [
        name
        for name, spec in (data.get("sensors") or {}).items()
        if str(spec.get("type", "")).endswith("Camera")
    ]


def make_camera(name: str, spec: str) -> Any:
    """A camera of ``--camera NAME=SPEC``: dummy[:WxH], an index, a device or a video file."""
    from poppy_core.sensors.camera import DummyCamera

    kind, _, size = spec.partition(":")
    if kind == "dummy":
        width, _, height = (size or "640x480").lower().partition("x")
        if not (width.isdigit() and height.isdigit()):
            raise usage(f"{spec!r}: give dummy:WIDTHxHEIGHT", "--camera")
        return DummyCamera(name, (int(width), int(height)), 30.0)
    from poppy_core.extras import require

    require("cv2", extra="vision", feature="cameras")
    from poppy_core.sensors.opencv_capture import OpenCVCamera

    return OpenCVCamera(name, int(spec) if spec.isdigit() else spec, 30.0)


def open_writer(folder: Path, spec: DatasetSpec, resume: bool) -> Any:
    from poppy_core.dataset.writer import DatasetWriter

    if resume:
        return core(lambda: DatasetWriter.resume(folder, spec), "--resume")
    return core(lambda: DatasetWriter.create(folder, spec), "--root")


def record_episodes(config: RobotConfig, sim: str | None, plan: Plan) -> dict[str, Any]:
    """Build everything, record ``plan.episodes`` episodes; the summary."""
    from poppy_cli.commands.dataset.live import Keys, Live
    from poppy_cli.robots import start_robot
    from poppy_core.dataset.layout import DatasetSpec
    from poppy_core.motion.episodes import EpisodeRecorder
    from poppy_core.sensors import Camera

    with ExitStack() as stack:
        leader = (
            open_leader(stack, plan.leader, plan.leader_port, plan.connect)
            if plan.leader is not None and plan.leader.startswith("zenoh:")
            else None
        )
        robot = stack.enter_context(start_robot(config, sim, sensors=plan.use_robot_cameras))
        chosen: dict[str, Any] = {}
        robot_cameras = {s.name: s for s in robot.sensors if isinstance(s, Camera)}
        if not plan.no_cameras:
            names = [n for n, s in plan.cameras.items() if s is None] or (
                list(robot_cameras) if not plan.cameras else []
            )
            chosen = {name: robot_cameras[name] for name in names}
            for name, spec in plan.cameras.items():
                if spec is not None:
                    made = make_camera(name, spec)
                    stack.callback(made.close)
                    chosen[name] = made
        motors = list(config.motors)
        sizes = {name: cam.frame.shape[:2] for name, cam in chosen.items()}  # waits for a frame
        spec = core(
            lambda: DatasetSpec(
                plan.fps,
                tuple(motors),
                {n: (int(h), int(w)) for n, (h, w) in sizes.items()},
                config.profile.name if config.profile is not None else None,
            ),
            "--camera",
        )
        writer = open_writer(plan.folder, spec, plan.resume)
        stack.callback(writer.close)
        if plan.leader is not None and leader is None:
            leader = open_leader(stack, plan.leader, plan.leader_port, plan.connect)
        actions = action_source(robot, motors, plan.source, plan.move, plan.primitive, leader)
        recorder = EpisodeRecorder(robot, writer, motors, chosen, actions)
        keys = Keys()
        keys.install(stack)
        live = Live(plan.episodes, plan.episode_s, show=plan.show)
        err_console.print(
            f"recording {plan.episodes} episode(s) of {plan.episode_s:g} s at {plan.fps} fps "
            f"into {plan.folder} (cameras: {', '.join(chosen) or 'none'}) — {live.hint(keys)}",
            soft_wrap=True,
            highlight=False,
            markup=False,
        )
        saved, dropped = _episodes(recorder, keys, live, plan)
    return {
        "root": str(plan.folder),
        "repo_id": plan.repo_id,
        "saved": [
            {"episode": e.index, "frames": e.frames, "duration_s": round(e.duration_s, 3)}
            for e in saved
        ],
        "frames": sum(e.frames for e in saved),
        "dropped": dropped,
        "total_episodes": len(writer.episodes),
    }


def _episodes(recorder: Any, keys: Keys, live: Live, plan: Plan) -> tuple[list[Any], int]:
    """The session's episodes (``recording_session``); the saved ones and frames dropped."""
    from poppy_core.motion.recording_session import RecordingSession, SessionPlan

    session = RecordingSession(
        recorder,
        SessionPlan(plan.task, plan.episodes, plan.episode_s, plan.reset_s),
        keys,
        live,
    )
    saved = session.run()
    return saved, session.dropped
