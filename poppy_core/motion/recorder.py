"""``MoveRecorder``: samples motor positions in a thread and checkpoints the move to disk.

Samples are taken at ``freq`` from the positions the sync loops last read, time-stamped, and
resampled onto the regular frame grid when the move is built, so a late tick does not shift
the frames. With a ``checkpoint_path`` the move so far is written atomically every
``checkpoint_period_s``: a recording cut short by a signal or a crash keeps everything up to
the last checkpoint, and ``stop()`` writes the final move.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable, Mapping, Sequence
from datetime import UTC, datetime
from pathlib import Path
from types import TracebackType
from typing import TYPE_CHECKING, Any

import numpy as np

from poppy_core.errors import ArgumentError
from poppy_core.motion.move import MAX_FRAMERATE_HZ, MIN_FRAMERATE_HZ, Move, resample
from poppy_core.motion.move_format import write_move
from poppy_core.robot.schedule import Periodic

if TYPE_CHECKING:
    from poppy_core.robot import Motor, Robot

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
        with_speeds: also record present speeds (pypot files carry them).
        metadata: header fields stored with the move (``created`` and ``robot`` are added).
        clock: the time source (seconds).

    Raises:
        ConfigError: an unknown motor or group name.
        ArgumentError: a frequency out of range.
    """

    def __init__(
        self,
        robot: Robot,
        freq: float = DEFAULT_FREQ_HZ,
        motors: Sequence[Motor | str] | None = None,
        *,
        checkpoint_path: str | Path | None = None,
        checkpoint_period_s: float = DEFAULT_CHECKPOINT_S,
        with_speeds: bool = False,
        metadata: Mapping[str, Any] | None = None,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        if not MIN_FREQ_HZ <= freq <= MAX_FREQ_HZ:  # also refuses NaN
            raise ArgumentError(
                f"the recording frequency must be {MIN_FREQ_HZ:g}-{MAX_FREQ_HZ:g} Hz, got {freq}",
                field="freq", value=freq,
            )  # fmt: skip
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
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._t0 = 0.0
        self.checkpoints = 0
        self.checkpoint_error: Exception | None = None

    # -- control -----------------------------------------------------------------------------

    def start(self) -> MoveRecorder:
        """Start recording in a thread (a new recording: earlier samples are dropped).

        Raises:
            RuntimeError: already recording.
        """
        if self.recording:
            raise RuntimeError("the recorder is already recording")
        self._samples = _Samples(self._samples.data.shape[1])
        self._metadata.setdefault("created", datetime.now(UTC).isoformat(timespec="seconds"))
        self._stop.clear()
        self._t0 = self._clock()
        self._thread = threading.Thread(target=self._run, name="move recorder", daemon=True)
        self._thread.start()
        return self

    def stop(self) -> Move:
        """Stop recording, write the last checkpoint and return the move."""
        thread = self._thread
        self._stop.set()
        if thread is not None and thread is not threading.current_thread():
            thread.join(timeout=5.0)
        self._thread = None
        move = self.move
        if self.checkpoint_path is not None and len(move):
            write_move(move, self.checkpoint_path)
            self.checkpoints += 1
        return move

    @property
    def recording(self) -> bool:
        """True while the thread runs."""
        return self._thread is not None and self._thread.is_alive()

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
            write_move(self.move, self.checkpoint_path)
            self.checkpoints += 1
        except Exception as exc:  # keep recording in memory; stop() tries again
            self.checkpoint_error = exc
            logger.warning("checkpoint to %s failed: %s", self.checkpoint_path, exc)

    def _run(self) -> None:
        schedule = Periodic(1.0 / self.freq, self._t0)
        next_checkpoint = self._t0 + self.checkpoint_period_s
        while not self._stop.is_set():
            now = self._clock()
            self._sample(now)
            if now >= next_checkpoint:
                self._checkpoint()
                next_checkpoint = now + self.checkpoint_period_s
            schedule.advance(self._clock())
            self._stop.wait(max(0.0, schedule.next_deadline - self._clock()))

    # -- context manager -----------------------------------------------------------------------

    def __enter__(self) -> MoveRecorder:
        return self.start()

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.stop()


def resolve_motors(robot: Robot, motors: Sequence[Motor | str] | None) -> list[Motor]:
    """Motors from motor objects, motor names or group names (each once, in order).

    Raises:
        ConfigError: an unknown motor or group name.
    """
    if motors is None:
        return robot.motors
    chosen: list[Motor] = []
    groups = robot.motorgroups
    for item in motors:
        if isinstance(item, str):
            found = groups[item] if item in groups else [robot.motor(item)]
        else:
            found = [item]
        chosen.extend(m for m in found if m not in chosen)
    return chosen
