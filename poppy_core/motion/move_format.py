"""Move files: poppy's compact binary format and pypot's JSON (written by ``poppy_core.files``).

poppy's format (``.move``), little-endian::

    8 bytes   magic  b"POPPYMOV"
    4 bytes   uint32 length H of the header
    H bytes   header: UTF-8 JSON object (see ``HEADER_KEYS``; extra keys are the move's metadata)
    N*M*4     positions, float32, frame after frame (N frames of M motors), degrees
    N*M*4     speeds in deg/s, same layout, only when the header says ``"speeds": true``

Loading is one read, one small JSON parse and a zero-copy ``numpy.frombuffer``, so a 10-minute
25-motor 50 Hz move loads in milliseconds. float32 keeps about 1e-5° at 180°, far below a
servo's resolution (0.088° on MX/X, 0.29° on AX/XL-320).

pypot's format (``.json``, written by ``pypot.primitive.move.Move.save``)::

    {"framerate": 50.0, "positions": {"0.0": {"m1": [pos, speed], ...}, "0.02": {...}, ...}}

keys are times in seconds written as float strings. Recorded keys are the recorder's elapsed
times, so they are not exactly evenly spaced: we sort them and, when they stray more than half
a period from the regular grid, resample linearly at the framerate.
"""

from __future__ import annotations

import json
import logging
import math
import os
import struct
from pathlib import Path
from typing import Any

import numpy as np

from poppy_core.documents import Limits, parse_json, read_limited
from poppy_core.errors import ArgumentError, ConfigError
from poppy_core.files import write_file
from poppy_core.motion.move import MAX_VALUES, Move, check_size, resample

logger = logging.getLogger(__name__)

MAGIC = b"POPPYMOV"
FORMAT_NAME = "poppy-move"
FORMAT_VERSION = 1
MOVE_SUFFIX = ".move"
PYPOT_SUFFIX = ".json"
FORMATS: tuple[str, ...] = ("poppy", "pypot")
HEADER_KEYS: tuple[str, ...] = (
    "format", "version", "framerate", "motors", "frames", "dtype", "speeds", "units",
)  # fmt: skip
_DTYPES: dict[str, np.dtype[Any]] = {"<f4": np.dtype("<f4"), "<f8": np.dtype("<f8")}
_LENGTH = struct.Struct("<I")
MAX_HEADER_BYTES = 1 << 20
MAX_MOVE_BYTES = 2 * MAX_VALUES * 8 + MAX_HEADER_BYTES
"""The largest .move file: the largest move in float64 with speeds."""
PYPOT_LIMITS = Limits(max_bytes=64 << 20, max_nodes=4 * MAX_VALUES, max_depth=8)
"""A pypot move JSON: 64 MiB holds 30 min of a 25-motor Humanoid at 50 Hz."""


_HEADER_LIMITS = Limits(max_bytes=MAX_HEADER_BYTES, max_nodes=100_000, max_depth=16)


def _bad(source: str, reason: str) -> ConfigError:
    return ConfigError(f"{source}: not a valid move file: {reason}", file=source, reason=reason)


# -- poppy's binary format ---------------------------------------------------------------------


def encode_move(move: Move, dtype: str = "<f4") -> bytes:
    """A move in poppy's binary format.

    Args:
        move: the move.
        dtype: ``"<f4"`` (float32, the default) or ``"<f8"`` (float64, exact).

    Returns:
        The file's bytes.
    """
    kind = _DTYPES[dtype]
    header: dict[str, Any] = {k: v for k, v in move.metadata.items() if k not in HEADER_KEYS}
    header.update(
        format=FORMAT_NAME,
        version=FORMAT_VERSION,
        framerate=move.framerate,
        motors=list(move.motors),
        frames=len(move),
        dtype=dtype,
        speeds=move.speeds is not None,
        units={"position": "deg", "speed": "deg/s"},
    )
    text = json.dumps(header, separators=(",", ":"), sort_keys=True, default=str).encode()
    parts = [MAGIC, _LENGTH.pack(len(text)), text, move.positions.astype(kind).tobytes()]
    if move.speeds is not None:
        parts.append(move.speeds.astype(kind).tobytes())
    return b"".join(parts)


def decode_move(data: bytes, source: str = "<bytes>") -> Move:
    """Read poppy's binary format.

    Raises:
        ConfigError: not a poppy move, a newer version, or a truncated/corrupt file.
    """
    if not data.startswith(MAGIC):
        raise _bad(source, "it does not start with the poppy move magic")
    start = len(MAGIC) + _LENGTH.size
    if len(data) < start:
        raise _bad(source, "truncated header")
    (length,) = _LENGTH.unpack_from(data, len(MAGIC))
    if length > MAX_HEADER_BYTES:
        raise _bad(source, f"a {length:,}-byte header (at most {MAX_HEADER_BYTES:,})")
    if len(data) < start + length:
        raise _bad(source, "truncated header")
    try:
        header = parse_json(data[start : start + length], source, _HEADER_LIMITS)
    except ConfigError as exc:
        raise _bad(source, f"unreadable header ({exc.reason})") from None
    if not isinstance(header, dict) or header.get("format") != FORMAT_NAME:
        raise _bad(source, "the header is not a poppy-move header")
    version = header.get("version")
    if not isinstance(version, int) or version > FORMAT_VERSION:
        raise _bad(source, f"format version {version!r} (this poppy reads {FORMAT_VERSION})")
    try:
        motors = [str(m) for m in header["motors"]]
        frames = int(header["frames"])
        kind = _DTYPES[str(header.get("dtype", "<f4"))]
        framerate = float(header["framerate"])
    except (KeyError, TypeError, ValueError, OverflowError) as exc:
        raise _bad(source, f"bad header field {exc}") from None
    try:
        check_size(framerate, frames, len(motors))
    except ArgumentError as exc:
        raise _bad(source, str(exc)) from None
    count = frames * len(motors)
    blocks = 2 if header.get("speeds") else 1
    body = start + length
    expected = body + blocks * count * kind.itemsize
    if frames < 0 or len(data) != expected:
        raise _bad(source, f"{len(data)} bytes where the header announces {expected}")
    shape = (frames, len(motors))
    positions = np.frombuffer(data, dtype=kind, count=count, offset=body).reshape(shape)
    speeds = None
    if blocks == 2:
        offset = body + count * kind.itemsize
        speeds = np.frombuffer(data, dtype=kind, count=count, offset=offset).reshape(shape)
    metadata = {k: v for k, v in header.items() if k not in HEADER_KEYS}
    try:
        return Move(framerate, motors, positions, speeds=speeds, metadata=metadata)
    except ValueError as exc:
        raise _bad(source, str(exc)) from None


# -- pypot's JSON ------------------------------------------------------------------------------


def encode_pypot(move: Move) -> bytes:
    """A move as pypot's move JSON (``[position, speed]`` per motor; speed 0 when unknown)."""
    speeds = move.speeds if move.speeds is not None else np.zeros_like(move.positions)
    timed: dict[str, dict[str, list[float]]] = {}
    pos_rows = move.positions.tolist()
    speed_rows = speeds.tolist()
    for index in range(len(move)):
        row = zip(move.motors, pos_rows[index], speed_rows[index], strict=True)
        timed[repr(index / move.framerate)] = {name: [pos, speed] for name, pos, speed in row}
    return json.dumps({"framerate": move.framerate, "positions": timed}).encode()


def _value_pair(value: Any) -> tuple[float, float]:
    if isinstance(value, int | float) and not isinstance(value, bool):
        return float(value), 0.0
    if isinstance(value, list | tuple) and value:
        speed = value[1] if len(value) > 1 else 0.0
        return float(value[0]), float(speed if speed is not None else 0.0)
    raise ValueError(f"{value!r} is not [position, speed]")


def decode_pypot(data: bytes | str, source: str = "<json>") -> Move:
    """Read pypot's move JSON (keys sorted as times; irregular times are resampled).

    Raises:
        ConfigError: not pypot move JSON.
    """
    if len(data) > PYPOT_LIMITS.max_bytes:
        raise _bad(source, f"{len(data):,} bytes of JSON (at most {PYPOT_LIMITS.max_bytes:,})")
    try:
        document = parse_json(data, source, PYPOT_LIMITS, check=False)
    except ConfigError as exc:
        raise _bad(source, str(exc.reason)) from None
    try:
        framerate = float(document["framerate"])
        timed = document["positions"]
        if not isinstance(timed, dict):
            raise TypeError("positions is not an object")
        items = sorted(((float(k), v) for k, v in timed.items()), key=lambda kv: kv[0])
    except (ValueError, KeyError, TypeError, OverflowError) as exc:
        raise _bad(source, f"not pypot move JSON ({type(exc).__name__}: {exc})") from None
    if not math.isfinite(framerate) or framerate <= 0:
        raise _bad(source, f"framerate {framerate!r} is not a positive number")
    motors: dict[str, None] = {}
    for time_s, frame in items:
        if not isinstance(frame, dict):
            raise _bad(source, "a frame is not an object of motor positions")
        if not math.isfinite(time_s):
            raise _bad(source, f"frame time {time_s!r} is not a finite number")
        motors.update(dict.fromkeys(frame))
    try:  # the grid the frames are resampled on, checked before any array is made
        span = items[-1][0] - items[0][0] if items else 0.0
        grid = int(min(span * framerate, 1e12)) + 1  # inf-safe: a huge grid is refused below
        check_size(framerate, max(len(items), grid), len(motors))
    except ArgumentError as exc:
        raise _bad(source, str(exc)) from None
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
        raise _bad(source, str(exc)) from None
    for array in (positions, speeds):
        _fill_gaps(array)
    if len(items) > 1:
        grid = times[0] + np.arange(len(items)) / framerate
        if float(np.max(np.abs(times - grid))) > 0.5 / framerate:
            logger.info("%s: irregular frame times, resampling at %g Hz", source, framerate)
            positions = resample(times, positions, framerate)
            speeds = resample(times, speeds, framerate)
    try:
        return Move(framerate, names, positions, speeds=speeds, metadata={})
    except ValueError as exc:
        raise _bad(source, str(exc)) from None


def _fill_gaps(array: np.ndarray[Any, np.dtype[np.float64]]) -> None:
    """Fill a motor missing from some frames with its previous (else next) known value."""
    for column in range(array.shape[1]):
        values = array[:, column]
        known = np.flatnonzero(~np.isnan(values))
        if known.size == len(values) or known.size == 0:
            continue
        index = np.searchsorted(known, np.arange(len(values)), side="right") - 1
        values[:] = values[known[np.clip(index, 0, None)]]


# -- files -------------------------------------------------------------------------------------


def detect_format(data: bytes) -> str:
    """``"poppy"`` or ``"pypot"`` from a file's first bytes (``"unknown"`` otherwise)."""
    if data.startswith(MAGIC):
        return "poppy"
    if data.lstrip()[:1] == b"{":
        return "pypot"
    return "unknown"


def decode_any(data: bytes, source: str = "<bytes>") -> Move:
    """Read either format, recognised by its first bytes.

    Raises:
        ConfigError: neither format.
    """
    kind = detect_format(data)
    if kind == "poppy":
        return decode_move(data, source)
    if kind == "pypot":
        return decode_pypot(data, source)
    raise _bad(source, "neither a poppy .move file nor pypot move JSON")


def format_for_path(path: str | os.PathLike[str]) -> str:
    """``"pypot"`` for a ``.json`` path, ``"poppy"`` otherwise."""
    return "pypot" if Path(path).suffix.lower() == PYPOT_SUFFIX else "poppy"


def encode(move: Move, fmt: str) -> bytes:
    """A move in ``fmt`` (``"poppy"`` or ``"pypot"``).

    Raises:
        ValueError: an unknown format.
    """
    if fmt == "poppy":
        return encode_move(move)
    if fmt == "pypot":
        return encode_pypot(move)
    raise ValueError(f"move format must be one of {', '.join(FORMATS)}, not {fmt!r}")


def read_move(path: str | os.PathLike[str]) -> Move:
    """Load a move file of either format.

    Raises:
        ConfigError: the file is missing, unreadable or not a move.
    """
    return decode_any(read_bytes(path), str(path))


def read_bytes(path: str | os.PathLike[str]) -> bytes:
    """A move file's bytes.

    Raises:
        ConfigError: the file is missing, unreadable, not a regular file or too large.
    """
    return read_limited(path, MAX_MOVE_BYTES, "move")


def write_move(
    move: Move,
    path: str | os.PathLike[str],
    fmt: str | None = None,
    *,
    replace: bool = True,
    make_folder: bool = False,
) -> Path:
    """Write a move atomically (a reader sees the old file or the new one, never a mix).

    Args:
        move: the move.
        path: where to write.
        fmt: ``"poppy"`` or ``"pypot"``; from the suffix when None (``.json`` is pypot's).
        replace: replace an existing regular file.
        make_folder: create a missing folder (the library's).

    Returns:
        The path written.

    Raises:
        FileError: refused or failed (see ``poppy_core.files.write_file``).
    """
    target = Path(path)
    data = encode(move, fmt or format_for_path(target))
    return write_file(target, data, replace=replace, make_folder=make_folder)
