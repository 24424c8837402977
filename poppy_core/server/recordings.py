"""``DatasetRecordings``: a LeRobot dataset recorded on the served robot, one at a time.

The request is checked as ``poppy dataset record`` checks its options (the same core checks),
then the episodes run in a thread through ``recording_session.RecordingSession``, the loop the
CLI runs, steered by the same three controls (end the episode, record it again, stop). Sources:
the robot moved by hand (a ``dataset recording`` lease on every motor: strict goals are
refused), a library move (played through ``MoveService.play``: the move's lease, as a v1 play),
a primitive. The dataset goes to LeRobot's folder (``$HF_LEROBOT_HOME/REPO_ID``), as the CLI's
default. ``close`` (the server's shutdown) stops as Esc does: the episode under way is saved,
the finished ones kept, the dataset loadable.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from poppy_core.errors import ArgumentError
from poppy_core.motion.leases import Lease, MotorLeases
from poppy_core.server.errors import ApiError

if TYPE_CHECKING:
    from poppy_core.motion.recording_session import RecordingSession, SessionPlan
    from poppy_core.robot import Robot
    from poppy_core.server.moves import MoveService

logger = logging.getLogger(__name__)

SOURCES = ("by_hand", "move", "primitive")
STOP_ROUTE = "POST /api/v1/recording/stop"
CLOSE_WAIT_S = 60.0


@dataclass(frozen=True)
class DatasetRequest:
    """What a client asked to record (checked by ``DatasetRecordings.start``)."""

    repo_id: str
    task: str
    source: str
    move: str | None = None
    primitive: str | None = None
    episodes: Any = 1
    episode_s: Any = 20.0
    reset_s: Any = 5.0
    fps: Any = 30
    cameras: Sequence[str] | None = None
    """Cameras of the robot by name; None: every one."""
    resume: bool = False


def whole(value: Any) -> Any:
    """A JSON number that is a whole number as an int (30.0 -> 30); anything else as it is."""
    if isinstance(value, float) and value.is_integer():
        return int(value)
    return value


class Recording:
    """One recording under way (or ended): its session, writer, thread and outcome."""

    def __init__(self, request: DatasetRequest, folder: Path, cameras: list[str]) -> None:
        self.request, self.folder, self.cameras = request, folder, cameras
        self.session: RecordingSession | None = None
        self.writer: Any = None
        self.thread: threading.Thread | None = None
        self.error: str | None = None
        self.lease: Lease | None = None

    @property
    def active(self) -> bool:
        return self.thread is not None and self.thread.is_alive()

    def state(self) -> dict[str, Any]:
        base: dict[str, Any] = {
            "active": self.active,
            "repo_id": self.request.repo_id,
            "folder": str(self.folder),
            "task": self.request.task,
            "source": self.request.source,
            "cameras": self.cameras,
            "error": self.error,
        }
        if self.session is not None:
            base.update(self.session.status())
        if base.get("phase") == "done" and base["active"]:
            # the takes are in, the dataset is still being written: "done" once it is
            base["phase"] = "finishing"
        base["total_episodes"] = len(self.writer.episodes) if self.writer is not None else 0
        return base


class DatasetRecordings:
    """The served robot's dataset recording (one at a time); thread-safe."""

    def __init__(self, robot: Robot, moves: MoveService, leases: MotorLeases) -> None:
        self.robot, self.moves, self.leases = robot, moves, leases
        self._lock = threading.Lock()
        self._current: Recording | None = None
        self._starting = False
        self._closed = False

    def state(self) -> dict[str, Any]:
        """The recording under way, or the last one; ``{"active": false, "phase": "idle"}``."""
        current = self._current
        if current is None:
            return {"active": False, "phase": "idle"}
        return current.state()

    def press(self, key: str) -> dict[str, Any]:
        """A control of the recording under way (``recording_session.RIGHT``, ``LEFT``, ``ESC``).

        Raises:
            ApiError: ``conflict`` when no recording is under way.
        """
        current = self._current
        if current is None or not current.active or current.session is None:
            raise ApiError("conflict", "no recording under way", tip="POST /api/v1/recording")
        current.session.controls.press(key)
        return current.state()

    def stop(self) -> bool:
        """Stop the recording under way as Esc does, without waiting; False when none was."""
        from poppy_core.motion.recording_session import ESC

        current = self._current
        if current is None or not current.active or current.session is None:
            return False
        current.session.controls.press(ESC)
        return True

    def start(self, request: DatasetRequest, client: str = "") -> dict[str, Any]:
        """Check ``request``, build the recording and start its thread; its state.

        Raises:
            ApiError: ``conflict`` when a recording is under way (or the server stops),
                ``invalid`` for a bad input, ``unavailable`` without the ``dataset`` extra.
            ArgumentError, MotorLeasedError: as the checks and leases raise them.
        """
        with self._lock:
            if self._closed:
                raise ApiError("unavailable", "the server is stopping: nothing new starts")
            current = self._current
            if self._starting or (current is not None and current.active):
                busy = current is not None and current.active
                what = current.request.repo_id if busy and current is not None else "another"
                raise ApiError(
                    "conflict",
                    f"a recording ({what}) is under way: one at a time, stop it first",
                    tip=STOP_ROUTE,
                )
            self._starting = True
        try:
            recording = self._build(request, client)
            with self._lock:
                closed = self._closed
                if not closed:
                    self._current = recording
                    assert recording.thread is not None
                    recording.thread.start()
            if closed:  # the server stopped while this one was being built
                recording.writer.close()
                if recording.lease is not None:
                    self.leases.release(recording.lease)
                raise ApiError("unavailable", "the server is stopping: nothing new starts")
            return recording.state()
        finally:
            with self._lock:
                self._starting = False

    def _build(self, request: DatasetRequest, client: str) -> Recording:
        from poppy_core.dataset import layout
        from poppy_core.dataset.writer import default_root
        from poppy_core.extras import require
        from poppy_core.motion.recording_session import (
            SessionPlan,
            check_episodes,
            check_seconds,
        )

        layout.check_repo_id(request.repo_id)
        layout.check_task(request.task)
        fps = layout.check_fps(whole(request.fps))
        episodes = check_episodes(whole(request.episodes))
        episode_s = check_seconds(request.episode_s, "episode_s", 0.1)
        reset_s = check_seconds(request.reset_s, "reset_s", 0.0)
        cameras = self._cameras(request.cameras)
        start_source = self._source_check(request)
        folder = default_root(request.repo_id)
        if folder.exists() and not request.resume:
            raise ArgumentError(
                f"{folder} already exists: give resume to add episodes, or another repo_id",
                field="repo_id",
            )
        if request.resume and not (folder / layout.INFO_PATH).is_file():
            raise ArgumentError(
                f"{folder} holds no dataset to resume (no {layout.INFO_PATH})", field="resume"
            )
        require("pyarrow", "av", extra="dataset")
        recording = Recording(request, folder, list(cameras))
        holder = object()
        recording.lease = Lease(
            "dataset recording", request.repo_id, client, holder=holder, stop=STOP_ROUTE
        )
        plan = SessionPlan(request.task, episodes, episode_s, reset_s)
        try:
            source = start_source(recording.lease, client)
            writer = self._writer(folder, fps, cameras, request.resume)
        except BaseException:
            self.leases.release(recording.lease)
            raise
        recording.session = self._session(writer, cameras, source, plan)
        recording.writer = writer
        recording.thread = threading.Thread(
            target=self._run, args=(recording,), name=f"dataset {request.repo_id}", daemon=True
        )
        return recording

    def _cameras(self, names: Sequence[str] | None) -> dict[str, Any]:
        from poppy_core.sensors import Camera

        found = {s.name: s for s in self.robot.sensors if isinstance(s, Camera)}
        if names is None:
            return found
        for name in names:
            if name not in found:
                raise ArgumentError(
                    f"no camera {name!r} on this robot (cameras: {', '.join(found) or 'none'})",
                    field="cameras",
                    value=name,
                )
        return {name: found[name] for name in dict.fromkeys(names)}

    def _source_check(self, request: DatasetRequest) -> Any:
        """Check the source asked; a function making its ``ActionSource`` (lease, client)."""
        from poppy_core.motion import episodes

        motors = [m.name for m in self.robot.motors]
        given = {"move": request.move, "primitive": request.primitive}
        extra = [k for k, v in given.items() if v is not None and k != request.source]
        if request.source not in SOURCES or extra:
            raise ArgumentError(
                f"give one source: by_hand, move (with its name in move) or primitive "
                f"(with its name in primitive), not {request.source!r}"
                + (f" with {', '.join(extra)}" if extra else ""),
                field="source",
            )
        if request.source == "by_hand":

            def by_hand(lease: Lease, client: str) -> Any:
                self.leases.take(lease, motors)
                return episodes.ByHand(self.robot, motors)

            return by_hand
        if request.source == "move":
            name = request.move
            if name not in self.moves.names():
                known = ", ".join(self.moves.names()) or "none"
                raise ArgumentError(
                    f"no move {name!r} in the library (moves: {known})", field="move"
                )
            move = self.moves.load(str(name))
            missing = [m for m in move.motors if m not in motors]
            if missing:
                raise ArgumentError(
                    f"the robot lacks the move's motors {', '.join(missing)}", field="move"
                )

            def played(lease: Lease, client: str) -> Any:
                self.leases.check(move.motors, lease.holder)
                return episodes.Goals(
                    self.robot,
                    motors,
                    lambda: self.moves.play(
                        str(name), writer=lease.holder, client=client, refuse_playing=True
                    ),
                    lambda: self.moves.stop(str(name)),
                )

            return played
        from poppy_core.motion import attached_primitives

        primitives = attached_primitives(self.robot)
        if request.primitive not in primitives:
            known = ", ".join(primitives) or "none"
            raise ArgumentError(
                f"no primitive {request.primitive!r} on this robot (primitives: {known})",
                field="primitive",
            )
        primitive = primitives[str(request.primitive)]
        if primitive.is_alive():
            raise ApiError(
                "conflict",
                f"the primitive {primitive.name} is running: stop it first",
                tip=f"POST /api/v1/primitives/{primitive.name}/stop",
            )

        def run_primitive(lease: Lease, client: str) -> Any:
            return episodes.Goals(self.robot, motors, primitive.start, primitive.stop)

        return run_primitive

    def _writer(self, folder: Path, fps: int, cameras: dict[str, Any], resume: bool) -> Any:
        from poppy_core.dataset.layout import DatasetSpec
        from poppy_core.dataset.writer import DatasetWriter

        sizes = {name: cam.frame.shape[:2] for name, cam in cameras.items()}  # waits for one
        config = self.robot.config
        profile = config.profile.name if config is not None and config.profile else None
        spec = DatasetSpec(
            fps,
            tuple(m.name for m in self.robot.motors),
            {n: (int(h), int(w)) for n, (h, w) in sizes.items()},
            profile,
        )
        if resume:
            return DatasetWriter.resume(folder, spec)
        return DatasetWriter.create(folder, spec)

    def _session(
        self,
        writer: Any,
        cameras: dict[str, Any],
        source: Any,
        plan: SessionPlan,
    ) -> RecordingSession:
        from poppy_core.motion.episodes import EpisodeRecorder
        from poppy_core.motion.recording_session import RecordingSession

        motors = [m.name for m in self.robot.motors]
        recorder = EpisodeRecorder(self.robot, writer, motors, cameras, source)
        return RecordingSession(recorder, plan)

    def _run(self, recording: Recording) -> None:
        assert recording.session is not None
        try:
            recording.session.run()
        except Exception as exc:  # the state says it; the finished episodes stay saved
            recording.error = f"the recording stopped: {type(exc).__name__}: {exc}"
            logger.warning("dataset %s: %s", recording.request.repo_id, recording.error)
        finally:
            try:
                recording.writer.close()
            finally:
                if recording.lease is not None:
                    self.leases.release(recording.lease)
            saved = recording.session.saved
            logger.info(
                "dataset %s: %d episode(s) saved in %s",
                recording.request.repo_id,
                len(saved),
                recording.folder,
            )

    def close(self) -> None:
        """Stop the recording under way as Esc does (its episode saved) and wait for it."""
        from poppy_core.motion.recording_session import ESC

        with self._lock:
            self._closed = True
            current = self._current
        if current is None or current.session is None or current.thread is None:
            return
        current.session.controls.press(ESC)
        current.thread.join(CLOSE_WAIT_S)
        if current.thread.is_alive():
            logger.warning(
                "dataset %s: the recording did not stop in %.0f s",
                current.request.repo_id,
                CLOSE_WAIT_S,
            )
