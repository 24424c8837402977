"""The bounds of a move (framerate, motors, values, duration) and the resampling of samples
taken at irregular times: the ground ``Move`` and the move file formats stand on."""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from poppy_core.errors import ArgumentError
from poppy_core.trajectory import MAX_DURATION_S

FloatArray = npt.NDArray[np.float64]

# Bounds of a move, checked before any array is allocated so that a tiny file cannot claim a huge
# move (a pypot JSON with framerate 1e6 resampled to 1.6 GB, a 1e-300 Hz move that never ends).
MIN_FRAMERATE_HZ = 0.1
MAX_FRAMERATE_HZ = 1000.0
MAX_MOTORS = 1024
MAX_VALUES = 5_000_000
"""Frames x motors (40 MB of float64 per array): 66 min of a 25-motor Humanoid at 50 Hz."""
MAX_POSITION_DEG = 1000.0
"""No servo turns further from its zero, offsets included; larger values are corrupt data."""
MAX_SPEED_DPS = 100_000.0


def check_size(framerate: float, frames: int, motors: int) -> None:
    """Refuse a move too large or too long to hold, before its arrays are allocated.

    Raises:
        ArgumentError: a framerate out of ``MIN_FRAMERATE_HZ``-``MAX_FRAMERATE_HZ``, more than
            ``MAX_MOTORS`` motors, more than ``MAX_VALUES`` values or longer than a day.
    """
    if not MIN_FRAMERATE_HZ <= framerate <= MAX_FRAMERATE_HZ:  # also refuses NaN
        raise ArgumentError(
            f"framerate must be {MIN_FRAMERATE_HZ:g}-{MAX_FRAMERATE_HZ:g} Hz, got {framerate:g}",
            field="framerate",
            value=framerate,
        )
    if motors > MAX_MOTORS:
        raise ArgumentError(
            f"{motors} motors: a move holds at most {MAX_MOTORS}", field="motors", value=motors
        )
    if frames < 0 or frames * max(motors, 1) > MAX_VALUES:
        raise ArgumentError(
            f"{frames} frames of {motors} motors: a move holds at most {MAX_VALUES:,} values",
            field="frames",
            value=frames,
        )
    if (frames - 1) / framerate > MAX_DURATION_S:
        raise ArgumentError(
            f"{frames} frames at {framerate:g} Hz last {(frames - 1) / framerate:.3g} s: a move "
            f"lasts at most {MAX_DURATION_S:g} s",
            field="frames",
            value=frames,
        )


def resample(times_s: npt.ArrayLike, positions: npt.ArrayLike, framerate: float) -> FloatArray:
    """Positions sampled at irregular times, linearly resampled at ``framerate``.

    Args:
        times_s: increasing sample times (the first one becomes t = 0).
        positions: shape ``(samples, motors)``.
        framerate: frames per second of the result.

    Returns:
        Shape ``(frames, motors)``: frame ``k`` is the position at ``times_s[0] + k / framerate``,
        up to the last sample time.

    Raises:
        ArgumentError: the result would be too large (see ``check_size``), checked before it is
            allocated.
    """
    t = np.asarray(times_s, dtype=np.float64)
    values = np.asarray(positions, dtype=np.float64)
    if t.size == 0:
        return values.reshape(0, values.shape[1] if values.ndim == 2 else 0)
    span = float(t[-1] - t[0])
    # A small slack keeps a last sample that falls a hair before its frame's time.
    count = math.floor(span * framerate + 1e-6) + 1
    check_size(framerate, count, values.shape[1] if values.ndim == 2 else 0)
    grid = t[0] + np.arange(count, dtype=np.float64) / framerate
    out = np.empty((count, values.shape[1]), dtype=np.float64)
    for column in range(values.shape[1]):
        out[:, column] = np.interp(grid, t, values[:, column])
    return out
