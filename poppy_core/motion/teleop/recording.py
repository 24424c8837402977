"""``TrajectoryRecorder``: the follower's positions during a teleoperation, saved as a move.

Samples are time-stamped as they come (one per teleoperation tick), resampled onto the move's
frame grid when the move is built, and checkpointed atomically every ``checkpoint_period_s``, so
a teleoperation cut short keeps what it recorded up to the last checkpoint.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Mapping, Sequence
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np

from poppy_core.errors import FileError
from poppy_core.motion.move import Move, resample
from poppy_core.motion.move_format import write_move

logger = logging.getLogger(__name__)

DEFAULT_CHECKPOINT_S = 1.0


class TrajectoryRecorder:
    """Collects ``(time, positions)`` samples of some motors and writes them as a move.

    Args:
        path: the move file (format from its suffix).
        motors: the motor names, one column each.
        framerate: frames per second of the saved move.
        metadata: header fields of the move (``created`` is added).
        checkpoint_period_s: time between two checkpoints.
    """

    def __init__(
        self,
        path: str | Path,
        motors: Sequence[str],
        framerate: float,
        *,
        metadata: Mapping[str, Any] | None = None,
        checkpoint_period_s: float = DEFAULT_CHECKPOINT_S,
    ) -> None:
        self.path = Path(path)
        self.motors = list(motors)
        self.framerate = float(framerate)
        self.metadata = dict(metadata or {})
        self.metadata.setdefault("created", datetime.now(UTC).isoformat(timespec="seconds"))
        self.checkpoint_period_s = checkpoint_period_s
        self._times: list[float] = []
        self._rows: list[list[float]] = []
        self._lock = threading.Lock()
        self._next_checkpoint: float | None = None
        self.checkpoints = 0

    def sample(self, time_s: float, positions: Mapping[str, float]) -> None:
        """Add the positions at ``time_s`` (motors missing from ``positions`` skip the sample);
        writes a checkpoint when one is due."""
        if any(name not in positions for name in self.motors):
            return
        with self._lock:
            self._times.append(time_s)
            self._rows.append([float(positions[name]) for name in self.motors])
        if self._next_checkpoint is None:
            self._next_checkpoint = time_s + self.checkpoint_period_s
        elif time_s >= self._next_checkpoint:
            self._next_checkpoint = time_s + self.checkpoint_period_s
            try:
                self.save()
            except (FileError, OSError) as exc:  # keep recording in memory; the final save retries
                logger.warning("checkpoint to %s failed: %s", self.path, exc)

    @property
    def samples(self) -> int:
        """Samples taken so far."""
        return len(self._times)

    def move(self) -> Move:
        """The move so far, resampled onto the frame grid."""
        with self._lock:
            times = np.array(self._times, dtype=np.float64)
            rows = np.array(self._rows, dtype=np.float64).reshape(len(self._rows), len(self.motors))
        positions = resample(times, rows, self.framerate)
        return Move(self.framerate, self.motors, positions, metadata=self.metadata)

    def save(self) -> Path | None:
        """Write the move so far atomically (nothing before the first sample).

        Raises:
            FileError: the file cannot be written (the samples are kept for another try).
        """
        move = self.move()
        if not len(move):
            return None
        write_move(move, self.path, make_folder=True)
        self.checkpoints += 1
        return self.path
