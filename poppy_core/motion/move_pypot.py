"""pypot's move JSON, read into and written from plain arrays (``Move`` builds on it).

The format (``.json``, written by ``pypot.primitive.move.Move.save``)::

    {"framerate": 50.0, "positions": {"0.0": {"m1": [pos, speed], ...}, "0.02": {...}, ...}}

keys are times in seconds written as float strings. Recorded keys are the recorder's elapsed
times, so they are not exactly evenly spaced: we sort them and, when they stray more than half
a period from the regular grid, resample linearly at the framerate.
"""

from __future__ import annotations

import json
import logging
import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from poppy_core.documents import Limits, parse_json
from poppy_core.errors import ArgumentError, ConfigError
from poppy_core.motion.move_bounds import MAX_VALUES, FloatArray, check_size, resample

logger = logging.getLogger(__name__)

PYPOT_LIMITS = Limits(max_bytes=64 << 20, max_nodes=4 * MAX_VALUES, max_depth=8)
"""A pypot move JSON: 64 MiB holds 30 min of a 25-motor Humanoid at 50 Hz."""


def bad_move(source: str, reason: str) -> ConfigError:
    """The error of a move file that cannot be read (its name and the reason)."""
    return ConfigError(f"{source}: not a valid move file: {reason}", file=source, reason=reason)


def pypot_json(
    framerate: float, motors: Sequence[str], positions: FloatArray, speeds: FloatArray | None
) -> bytes:
    """pypot's move JSON of ``positions`` (``[position, speed]`` per motor; speed 0 unknown)."""
    speeds = speeds if speeds is not None else np.zeros_like(positions)
    timed: dict[str, dict[str, list[float]]] = {}
    pos_rows = positions.tolist()
    speed_rows = speeds.tolist()
    for index in range(len(pos_rows)):
        row = zip(motors, pos_rows[index], speed_rows[index], strict=True)
        timed[repr(index / framerate)] = {name: [pos, speed] for name, pos, speed in row}
    return json.dumps({"framerate": framerate, "positions": timed}).encode()


def _value_pair(value: Any) -> tuple[float, float]:
    if isinstance(value, int | float) and not isinstance(value, bool):
        return float(value), 0.0
    if isinstance(value, list | tuple) and value:
        speed = value[1] if len(value) > 1 else 0.0
        return float(value[0]), float(speed if speed is not None else 0.0)
    raise ValueError(f"{value!r} is not [position, speed]")


def parse_pypot(
    data: bytes | str, source: str = "<json>"
) -> tuple[float, list[str], FloatArray, FloatArray]:
    """Read pypot's move JSON into (framerate, motors, positions, speeds), on a regular grid.

    Raises:
        ConfigError: not pypot move JSON, or a move too large to hold.
    """
    if len(data) > PYPOT_LIMITS.max_bytes:
        raise bad_move(source, f"{len(data):,} bytes of JSON (at most {PYPOT_LIMITS.max_bytes:,})")
    try:
        document = parse_json(data, source, PYPOT_LIMITS, check=False)
    except ConfigError as exc:
        raise bad_move(source, str(exc.reason)) from None
    try:
        framerate = float(document["framerate"])
        timed = document["positions"]
        if not isinstance(timed, dict):
            raise TypeError("positions is not an object")
        items = sorted(((float(k), v) for k, v in timed.items()), key=lambda kv: kv[0])
    except (ValueError, KeyError, TypeError, OverflowError) as exc:
        raise bad_move(source, f"not pypot move JSON ({type(exc).__name__}: {exc})") from None
    if not math.isfinite(framerate) or framerate <= 0:
        raise bad_move(source, f"framerate {framerate!r} is not a positive number")
    motors: dict[str, None] = {}
    for time_s, frame in items:
        if not isinstance(frame, dict):
            raise bad_move(source, "a frame is not an object of motor positions")
        if not math.isfinite(time_s):
            raise bad_move(source, f"frame time {time_s!r} is not a finite number")
        motors.update(dict.fromkeys(frame))
    try:  # the grid the frames are resampled on, checked before any array is made
        span = items[-1][0] - items[0][0] if items else 0.0
        grid = int(min(span * framerate, 1e12)) + 1  # inf-safe: a huge grid is refused below
        check_size(framerate, max(len(items), grid), len(motors))
    except ArgumentError as exc:
        raise bad_move(source, str(exc)) from None
    times = np.array([t for t, _ in items], dtype=np.float64)
    positions = np.full((len(items), len(motors)), np.nan)
    speeds = np.full((len(items), len(motors)), np.nan)
    column = {m: i for i, m in enumerate(motors)}
    names = list(motors)
    try:
        for row, (_, frame) in enumerate(items):
            for name, value in frame.items():
                positions[row, column[name]], speeds[row, column[name]] = _value_pair(value)
    except (ValueError, TypeError, OverflowError) as exc:
        raise bad_move(source, str(exc)) from None
    for array in (positions, speeds):
        _fill_gaps(array)
    if len(items) > 1:
        grid = times[0] + np.arange(len(items)) / framerate
        if float(np.max(np.abs(times - grid))) > 0.5 / framerate:
            logger.info("%s: irregular frame times, resampling at %g Hz", source, framerate)
            positions = resample(times, positions, framerate)
            speeds = resample(times, speeds, framerate)
    return framerate, names, positions, speeds


def _fill_gaps(array: np.ndarray[Any, np.dtype[np.float64]]) -> None:
    """Fill a motor missing from some frames with its previous (else next) known value."""
    for column in range(array.shape[1]):
        values = array[:, column]
        known = np.flatnonzero(~np.isnan(values))
        if known.size == len(values) or known.size == 0:
            continue
        index = np.searchsorted(known, np.arange(len(values)), side="right") - 1
        values[:] = values[known[np.clip(index, 0, None)]]
