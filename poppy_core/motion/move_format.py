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

pypot's format (``.json``, written by ``pypot.primitive.move.Move.save``) is read and written by
``move_pypot`` (below ``Move``, whose pypot ``save``/``load``/``loads`` use it).
"""

from __future__ import annotations

import json
import logging
import os
import struct
from pathlib import Path
from typing import Any

import numpy as np

from poppy_core.documents import Limits, parse_json, read_limited
from poppy_core.errors import ArgumentError, ConfigError
from poppy_core.files import write_file
from poppy_core.motion.move import Move
from poppy_core.motion.move_bounds import MAX_VALUES, check_size
from poppy_core.motion.move_pypot import bad_move, pypot_json

logger = logging.getLogger(__name__)

MAGIC = b"POPPYMOV"
FORMAT_NAME = "poppy-move"
FORMAT_VERSION = 1
MOVE_SUFFIX = ".move"
PYPOT_SUFFIX = ".json"
FORMATS: tuple[str, ...] = ("poppy", "pypot")
HEADER_KEYS: tuple[str, ...] = (
    "format",
    "version",
    "framerate",
    "motors",
    "frames",
    "dtype",
    "speeds",
    "units",
)
_DTYPES: dict[str, np.dtype[Any]] = {"<f4": np.dtype("<f4"), "<f8": np.dtype("<f8")}
_LENGTH = struct.Struct("<I")
MAX_HEADER_BYTES = 1 << 20
MAX_MOVE_BYTES = 2 * MAX_VALUES * 8 + MAX_HEADER_BYTES
"""The largest .move file: the largest move in float64 with speeds."""


_HEADER_LIMITS = Limits(max_bytes=MAX_HEADER_BYTES, max_nodes=100_000, max_depth=16)


_bad = bad_move


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
    return pypot_json(move.framerate, move.motors, move.positions, move.speeds)


def decode_pypot(data: bytes | str, source: str = "<json>") -> Move:
    """Read pypot's move JSON (keys sorted as times; irregular times are resampled).

    Raises:
        ConfigError: not pypot move JSON.
    """
    return Move.loads(data, source)


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
