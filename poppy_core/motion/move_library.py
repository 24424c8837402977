"""The move library: a folder of moves (platformdirs user data, or ``POPPY_MOVES_DIR``) by name.

A *name* is a file stem in the library (``wave`` → ``<library>/wave.move``, or ``wave.json`` for
a pypot file dropped there); anything with a folder part or a move suffix is a *path*.
"""

from __future__ import annotations

import os
import re
import tempfile
from dataclasses import dataclass
from datetime import datetime
from pathlib import Path

import platformdirs

from poppy_core.errors import ConfigError, FileError, UnknownMoveError
from poppy_core.files import output_path, write_file
from poppy_core.motion.move import Move
from poppy_core.motion.move_format import (
    MOVE_SUFFIX,
    PYPOT_SUFFIX,
    decode_any,
    detect_format,
    format_for_path,
    read_bytes,
    read_move,
    write_move,
)

MOVES_DIR_ENV = "POPPY_MOVES_DIR"
SUFFIXES: tuple[str, ...] = (MOVE_SUFFIX, PYPOT_SUFFIX)
_NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9._ -]*$")
MAX_NAME_CHARS = 100
"""Longest move name: file systems stop at 255 bytes, and a name is read by people."""


@dataclass(frozen=True)
class MoveEntry:
    """One move of the library."""

    name: str
    path: Path
    format: str
    size_bytes: int


def moves_dir() -> Path:
    """The library folder: ``$POPPY_MOVES_DIR``, else ``<user data dir>/poppy/moves``."""
    override = os.environ.get(MOVES_DIR_ENV)
    if override:
        return Path(override).expanduser()
    return Path(platformdirs.user_data_dir("poppy")) / "moves"


def library() -> Path:
    """The library folder, checked: it may be missing (no move yet) but not be something else.

    Raises:
        FileError: the path exists and is not a folder.
    """
    root = moves_dir()
    if root.exists() and not root.is_dir():
        raise FileError(
            f"the move library {root} is not a folder: remove it or set {MOVES_DIR_ENV} to a "
            "folder",
            path=str(root),
        )
    return root


def is_path(ref: str | os.PathLike[str]) -> bool:
    """True when ``ref`` names a file (folder part or move suffix), not a library name."""
    text = os.fspath(ref)
    return os.sep in text or "/" in text or Path(text).suffix.lower() in SUFFIXES


def check_name(name: str) -> str:
    """A valid library name (letters, digits, ``. _ -`` and spaces; no folder part).

    The one rule of move names: the CLI, the Python API and every server (REST, Snap!, ZMQ)
    check names with it, and the library lists only the files it accepts, so a move listed
    anywhere can be played, shown and deleted everywhere. A name starts with a letter or a
    digit and has no ``/``: it never names a hidden file or a path outside the library.

    Raises:
        ConfigError: a name that cannot be a file stem.
    """
    if len(name) > MAX_NAME_CHARS:
        raise ConfigError(
            f"a move name has at most {MAX_NAME_CHARS} characters ({len(name)} given)",
            field="name",
            value=name,
        )
    if not is_move_name(name):
        raise ConfigError(
            f"{name!r} is not a move name: use letters, digits, '.', '_', '-' or spaces",
            field="name",
            value=name,
        )
    return name


def is_move_name(name: str) -> bool:
    """True when ``check_name`` accepts ``name``."""
    return len(name) <= MAX_NAME_CHARS and bool(_NAME.match(name)) and not name.endswith((".", " "))


def list_moves(folder: Path | None = None) -> list[MoveEntry]:
    """The moves in the library, sorted by name (``.move`` first when both exist).

    A file whose stem is not a move name (``check_name``: ``wave (copy).move``) is left out:
    no command could name it (``poppy moves import FILE`` adds it under a name).
    """
    root = folder if folder is not None else library()
    if not root.is_dir():
        return []
    entries = []
    for path in root.iterdir():
        if path.suffix.lower() in SUFFIXES and is_move_name(path.stem) and path.is_file():
            entries.append(MoveEntry(path.stem, path, format_for_path(path), path.stat().st_size))
    return sorted(entries, key=lambda e: (e.name, SUFFIXES.index(e.path.suffix.lower())))


def move_path(ref: str | os.PathLike[str], *, must_exist: bool = True) -> Path:
    """The file a name or a path refers to.

    Args:
        ref: a library name or a path.
        must_exist: raise when there is no such move (else give the path a new move would take).

    Raises:
        UnknownMoveError: no such move (a ``ConfigError``).
    """
    if is_path(ref):
        path = Path(ref).expanduser()
        if must_exist and not path.is_file():
            raise UnknownMoveError(f"no move file {path}", name=str(path))
        return path
    name = check_name(os.fspath(ref))
    root = library()
    for suffix in SUFFIXES:
        candidate = root / f"{name}{suffix}"
        if candidate.is_file():
            return candidate
    if must_exist:
        known = [e.name for e in list_moves()]
        error = UnknownMoveError(
            f"no move {name!r} in {root} (moves: {', '.join(known) or 'none'})",
            name=name,
            known=known,
        )
        error.file = str(root)
        raise error
    return root / f"{name}{MOVE_SUFFIX}"


def load_move(ref: str | os.PathLike[str]) -> Move:
    """Load a move by library name or path (either format).

    Raises:
        ConfigError: no such move, or not a move file.
    """
    return read_move(move_path(ref))


def save_move(
    move: Move, ref: str | os.PathLike[str], fmt: str | None = None, *, replace: bool = True
) -> Path:
    """Save a move under a library name (poppy's format) or at a path (format from its suffix).

    The library folder is created when missing; a path's folder must exist.

    Args:
        move: the move.
        ref: a library name or a path.
        fmt: ``"poppy"`` or ``"pypot"`` (from the suffix when None).
        replace: replace an existing move file.

    Returns:
        The path written (atomically).

    Raises:
        ConfigError: a bad name.
        FileError: refused or failed (full disk, read-only folder...): nothing is replaced.
    """
    target = move_path(ref, must_exist=False)
    return write_move(move, target, fmt, replace=replace, make_folder=not is_path(ref))


def delete_move(ref: str | os.PathLike[str]) -> Path:
    """Delete a move by name or path.

    Returns:
        The path deleted.

    Raises:
        UnknownMoveError: no such move (a ``ConfigError``).
    """
    path = move_path(ref)
    path.unlink()
    return path


def fallback_path(name: str) -> Path:
    """Where a take goes when its destination failed: ``<temp dir>/poppy-take-<name>-<time>.move``.

    ``poppy record`` and a server stopping with takes not saved write there when the library
    cannot have them; ``poppy moves import`` brings such a file into the library.
    """
    stamp = datetime.now().strftime("%Y%m%d-%H%M%S")
    safe = name.replace("/", "_").replace(os.sep, "_")
    return Path(tempfile.gettempdir()) / f"poppy-take-{safe}-{stamp}{MOVE_SUFFIX}"


def import_move(
    source: str | os.PathLike[str], name: str | None = None, *, overwrite: bool = False
) -> Path:
    """Copy a move file (pypot JSON or ours) into the library, stored in poppy's format.

    Args:
        source: the file to import.
        name: its library name (default: the file's stem).
        overwrite: replace a move of that name.

    Returns:
        The new library file.

    Raises:
        ConfigError: not a move file, or the name is taken and ``overwrite`` is False.
    """
    src = Path(source).expanduser()
    move = read_move(src)
    target_name = check_name(name if name is not None else src.stem)
    existing = [library() / f"{target_name}{s}" for s in SUFFIXES]
    taken = [p for p in existing if p.is_file()]
    if taken and not overwrite:
        raise ConfigError(
            f"a move named {target_name!r} exists ({taken[0]}): choose another name or pass "
            "--force to replace it",
            file=str(taken[0]),
            field="name",
        )
    move.metadata.setdefault("imported_from", str(src))
    target = write_move(
        move,
        library() / f"{target_name}{MOVE_SUFFIX}",
        "poppy",
        replace=overwrite,
        make_folder=True,
    )
    for path in taken:
        if path != target:
            path.unlink()
    return target


def export_move(
    ref: str | os.PathLike[str],
    destination: str | os.PathLike[str],
    fmt: str | None = None,
    *,
    replace: bool = False,
) -> Path:
    """Write a library move (or any move file) to ``destination`` in ``fmt``.

    Args:
        ref: library name or path of the move.
        destination: the file to write, or a folder to write ``<name>.move``/``.json`` into.
        fmt: ``"poppy"`` or ``"pypot"``; from the destination's suffix when None (a folder:
            the move's own format).
        replace: replace an existing regular file.

    Returns:
        The path written.

    Raises:
        ConfigError: no such move, or not a move file.
        FileError: the destination is refused (it exists without ``replace``, is not a regular
            file, or its folder is missing) or the write failed.
    """
    source = move_path(ref)
    given = Path(destination).expanduser()
    into_folder = given.is_dir() and not given.is_symlink()
    chosen = fmt or (format_for_path(source) if into_folder else format_for_path(given))
    suffix = PYPOT_SUFFIX if chosen == "pypot" else MOVE_SUFFIX
    target = output_path(given, default_name=f"{source.stem}{suffix}", replace=True)
    if target.exists() and source.resolve() == target.resolve():
        raise FileError(f"{target} is the move itself: give another file", path=str(target))
    output_path(target, replace=replace)  # refused now, before the move is read and converted
    data = read_bytes(source)
    if chosen == "poppy" and detect_format(data) == "poppy":
        return write_file(target, data, replace=replace)  # already ours: copied byte for byte
    return write_move(decode_any(data, str(source)), target, chosen, replace=replace)
