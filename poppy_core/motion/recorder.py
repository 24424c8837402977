"""``MoveRecorder``: samples motor positions in a thread and checkpoints the move to disk.

Samples are taken at ``freq`` from the positions the sync loops last read (the first by
``start()`` itself, the last when ``stop()`` is called, so a busy machine neither delays nor
cuts the take), time-stamped, and resampled onto the regular frame grid when the move is built,
so a late tick does not shift the frames. With a ``checkpoint_path`` the move so far is
written atomically every ``checkpoint_period_s``: a recording cut short by a signal or a crash
keeps everything up to the last checkpoint, and ``stop()`` writes the final move.

Nothing recorded is lost to a bad destination: ``start()`` checks that the folder takes files
and locks the file against a second recorder; a checkpoint that fails (full disk, folder gone)
is reported once and the take stays in memory; when the final write fails ``stop()`` raises,
and the move is still there to ``save()`` elsewhere.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable, Mapping, Sequence
from datetime import UTC, datetime
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from poppy_core.errors import ArgumentError, FileError
from poppy_core.files import FileLock, output_path, probe_folder
from poppy_core.motion.move import MAX_FRAMERATE_HZ, MIN_FRAMERATE_HZ, Move, resample
from poppy_core.motion.move_format import MOVE_SUFFIX, write_move
from poppy_core.schedule import Ticker, Worker

if TYPE_CHECKING:
    from poppy_core.robot import Motor, Robot
    from poppy_core.robot.robot import MotorSpec

logger = logging.getLogger(__name__)

DEFAULT_FREQ_HZ = 50.0
DEFAULT_CHECKPOINT_S = 1.0
MIN_FREQ_HZ = MIN_FRAMERATE_HZ
MAX_FREQ_HZ = MAX_FRAMERATE_HZ
_INITIAL_CAPACITY = 1024


class _Samples:
    """A growable ``(time, positions..., speeds...)`` buffer (amortised O(1) appends)."""

    def __init__(self, width: int) -> None:
        self.data = np.empty((_INITIAL_CAPACITY, width), dtype=np.float64)
        self.count = 0

    def append(self, row: Sequence[float]) -> None:
        if self.count == self.data.shape[0]:
            grown = np.empty((self.data.shape[0] * 2, self.data.shape[1]), dtype=np.float64)
            grown[: self.count] = self.data[: self.count]
            self.data = grown
        self.data[self.count] = row
        self.count += 1

    def view(self) -> np.ndarray[Any, np.dtype[np.float64]]:
        return self.data[: self.count]


class MoveRecorder:
    """Records the positions of some motors of a robot into a ``Move``.

    The recorder does not touch compliance: make the motors compliant first to move them by
    hand.

    Args:
        robot: the robot.
        freq: frames per second (the move's framerate).
        motors: motors or motor/group names to record (default: every motor).
        checkpoint_path: write the move there (format from the suffix) while recording.
        checkpoint_period_s: time between two checkpoints.
        replace: the checkpoint may replace a file already at ``checkpoint_path``.
        make_folder: create the checkpoint's missing folder (the library's).
        with_speeds: also record present speeds (pypot files carry them).
        metadata: header fields stored with the move (``created`` and ``robot`` are added).
        clock: the time source (seconds).

    Raises:
        ConfigError: an unknown motor or group name.
        ArgumentError: a frequency out of range.

    Attributes:
        saved_path: where ``stop()`` or ``save()`` last wrote the move.
        checkpoint_error: the last checkpoint's failure (None once one works again).
    """

    def __init__(
        self,
        robot: Robot,
        freq: float = DEFAULT_FREQ_HZ,
        motors: MotorSpec | None = None,
        *,
        checkpoint_path: str | Path | None = None,
        checkpoint_period_s: float = DEFAULT_CHECKPOINT_S,
        replace: bool = True,
        make_folder: bool = False,
        with_speeds: bool = False,
        metadata: Mapping[str, Any] | None = None,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        if not MIN_FREQ_HZ <= freq <= MAX_FREQ_HZ:  # also refuses NaN
            raise ArgumentError(
                f"the recording frequency must be {MIN_FREQ_HZ:g}-{MAX_FREQ_HZ:g} Hz, got {freq}",
                field="freq",
                value=freq,
            )
        self.robot = robot
        self.freq = float(freq)
        self.motors = resolve_motors(robot, motors)
        self.checkpoint_path = Path(checkpoint_path) if checkpoint_path is not None else None
        self.checkpoint_period_s = checkpoint_period_s
        self.with_speeds = with_speeds
        self._metadata = dict(metadata or {})
        self._clock = clock
        width = 1 + len(self.motors) * (2 if with_speeds else 1)
        self._samples = _Samples(width)
        self._lock = threading.Lock()
        self._worker: Worker | None = None
        self._t0 = 0.0
        self._next_checkpoint = 0.0
        self.checkpoints = 0
        self.checkpoint_error: Exception | None = None
        self.saved_path: Path | None = None
        self._replace = replace
        self._make_folder = make_folder
        self._file_lock: FileLock | None = None

    # -- control -----------------------------------------------------------------------------

    def start(self) -> MoveRecorder:
        """Start recording in a thread (a new recording: earlier samples are dropped).

        Raises:
            RuntimeError: already recording.
            FileError: the checkpoint's folder does not take files (missing, read-only, full),
                or another process records into the same file; nothing was recorded.
        """
        if self.recording:
            raise RuntimeError("the recorder is already recording")
        if self.checkpoint_path is not None:
            probe_folder(self.checkpoint_path.parent, make_folder=self._make_folder)
            if self._file_lock is None:
                self._file_lock = FileLock(self.checkpoint_path).acquire()
        self.checkpoint_error = None
        self._samples = _Samples(self._samples.data.shape[1])
        self._metadata.setdefault("created", datetime.now(UTC).isoformat(timespec="seconds"))
        self._t0 = self._clock()
        self._sample(self._t0)  # the take starts now, not when the thread first gets the CPU
        self._worker = Worker("move recorder", self._run)  # one per take (see MovePlayer)
        self._worker.start()
        return self

    def stop(self) -> Move:
        """Stop recording, write the last checkpoint and return the move.

        Raises:
            FileError: the move could not be written to ``checkpoint_path``; it is still held
                (``move``) for ``save()`` to write elsewhere.
        """
        worker = self._worker
        if worker is not None:
            worker.close(5.0)  # joins (but from its own thread); an error was logged once
        move = self.move
        try:
            if self.checkpoint_path is not None and len(move):
                self._write(move, self.checkpoint_path)
        finally:
            if self._file_lock is not None:
                self._file_lock.release()
                self._file_lock = None
        return move

    def save(
        self, path: str | Path | None = None, *, replace: bool = False, make_folder: bool = False
    ) -> Path:
        """Write the move recorded so far (again, or somewhere else).

        Args:
            path: a file, or a folder to write ``<name>.move`` into; the checkpoint path when
                None (it is then replaced).
            replace: replace an existing file.
            make_folder: create a missing folder.

        Returns:
            The path written.

        Raises:
            FileError: refused or failed; the move is still held.
            ArgumentError: there is no path and no checkpoint path.
        """
        if path is None:
            if self.checkpoint_path is None:
                raise ArgumentError(
                    "give a path: this recorder has no checkpoint path", field="path"
                )
            target, replace = self.checkpoint_path, True
        else:
            name = self.checkpoint_path.name if self.checkpoint_path else f"take{MOVE_SUFFIX}"
            target = output_path(path, default_name=name, replace=replace, make_folder=make_folder)
        return self._write(self.move, target, replace=replace, make_folder=make_folder)

    def _write(
        self, move: Move, target: Path, *, replace: bool | None = None, make_folder: bool = False
    ) -> Path:
        """Write ``move``; the checkpoint file may be replaced once it is ours."""
        ours = target == self.checkpoint_path and (self._replace or self.checkpoints > 0)
        written = write_move(
            move,
            target,
            replace=ours if replace is None else replace,
            make_folder=make_folder or (target == self.checkpoint_path and self._make_folder),
        )
        if target == self.checkpoint_path:
            self.checkpoints += 1
        self.saved_path = written
        return written

    def add_tracked_motors(self, motors: MotorSpec) -> None:
        """Record these motors too (pypot's name); before ``start()`` only.

        Raises:
            ArgumentError: already recording.
            UnknownMotorError: a name the robot does not have.
        """
        if self.recording:
            raise ArgumentError(
                "add the motors before start(): a recording keeps its motors", field="motors"
            )
        added = [m for m in resolve_motors(self.robot, motors) if m not in self.motors]
        self.motors = [*self.motors, *added]
        self._samples = _Samples(1 + len(self.motors) * (2 if self.with_speeds else 1))

    @property
    def tracked_motors(self) -> list[Motor]:
        """The recorded motors (pypot's name)."""
        return list(self.motors)

    def wait_to_stop(self, timeout_s: float | None = None) -> bool:
        """Block until the recording thread ended (pypot's name)."""
        worker = self._worker
        if worker is not None:
            worker.wait(timeout_s)
        return not self.recording

    def is_alive(self) -> bool:
        """``recording`` (pypot's name)."""
        return self.recording

    @property
    def recording(self) -> bool:
        """True while the thread runs."""
        return self._worker is not None and self._worker.running

    @property
    def error(self) -> BaseException | None:
        """What ended the last take's thread early (logged once), None when nothing did."""
        return self._worker.error if self._worker is not None else None

    @property
    def frames_recorded(self) -> int:
        """Samples taken so far."""
        return self._samples.count

    @property
    def elapsed_s(self) -> float:
        """Time since the first sample (0 before)."""
        with self._lock:
            samples = self._samples.view()
            return float(samples[-1, 0] - samples[0, 0]) if len(samples) else 0.0

    def latest(self) -> dict[str, float]:
        """The last sampled positions (empty before the first sample)."""
        with self._lock:
            samples = self._samples.view()
            if not len(samples):
                return {}
            row = samples[-1]
        return {m.name: float(row[1 + i]) for i, m in enumerate(self.motors)}

    @property
    def move(self) -> Move:
        """The move recorded so far, resampled onto the frame grid."""
        with self._lock:
            samples = self._samples.view().copy()
        names = [m.name for m in self.motors]
        count = len(names)
        positions = resample(samples[:, 0], samples[:, 1 : 1 + count], self.freq)
        speeds = None
        if self.with_speeds:
            speeds = resample(samples[:, 0], samples[:, 1 + count :], self.freq)
        metadata = dict(self._metadata)
        config = self.robot.config
        if config is not None and config.profile is not None:
            metadata.setdefault("robot", config.profile.name)
        return Move(self.freq, names, positions, speeds=speeds, metadata=metadata)

    # -- thread ------------------------------------------------------------------------------

    def _sample(self, now: float) -> None:
        row = [now - self._t0]
        row.extend(m.present_position for m in self.motors)
        if self.with_speeds:
            row.extend(m.present_speed for m in self.motors)
        with self._lock:
            self._samples.append(row)

    def _checkpoint(self) -> None:
        if self.checkpoint_path is None:
            return
        try:
            self._write(self.move, self.checkpoint_path)
        except (FileError, OSError) as exc:  # the take stays in memory; stop() tries again
            if self.checkpoint_error is None:  # once per failing streak, not every second
                logger.warning(
                    "checkpoint to %s failed (the take is kept in memory): %s",
                    self.checkpoint_path,
                    exc,
                )
            self.checkpoint_error = exc
            return
        if self.checkpoint_error is not None:
            logger.warning("checkpoint to %s works again", self.checkpoint_path)
            self.checkpoint_error = None

    def _run(self, stopping: threading.Event) -> None:
        self._next_checkpoint = self._t0 + self.checkpoint_period_s
        # a sample that raises ends the take (kept, ``error`` says why): nothing retried
        ticker = Ticker("move recorder", self.freq, self._tick, clock=self._clock, retry=())
        ticker.run(stopping, self._t0 + 1.0 / self.freq)  # start() took the sample at t0
        self._sample(self._clock())  # the take ends at stop(), not at the last tick before it

    def _tick(self, now: float) -> None:
        self._sample(now)
        if now >= self._next_checkpoint:
            self._checkpoint()
            self._next_checkpoint = now + self.checkpoint_period_s

    # -- context manager -----------------------------------------------------------------------

    def __enter__(self) -> MoveRecorder:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()


def resolve_motors(robot: Robot, motors: MotorSpec | None) -> list[Motor]:
    """Motors from motor objects, motor names or group names (each once, in order); a name
    alone is one motor or group.

    Raises:
        UnknownMotorError: an unknown motor or group name.
    """
    return robot.motors_of(motors)
