"""Reading JSON and YAML documents from users without hanging, crashing or eating memory.

A config or a move file is read whole, so its size is bounded first (``read_limited``); then it is
parsed (``parse_json``, ``parse_yaml``) and its shape checked (``check_shape``) before anyone walks
it: at most ``max_depth`` levels of nesting and ``max_nodes`` values once YAML aliases are
expanded. A 358-byte YAML "billion laughs" names only a few nodes but expands to billions: it is
refused in microseconds here, where validating or printing it took minutes and gigabytes. A
document that nests deeper than Python's recursion allows, or holds an integer of thousands of
digits, is a one-line ``ConfigError`` too, never a ``RecursionError`` or a ``ValueError``.
"""

from __future__ import annotations

import copy
import json
import os
import stat
import threading
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

import yaml

from poppy_core.errors import ConfigError


@dataclass(frozen=True)
class Limits:
    """What a kind of document may hold.

    Attributes:
        max_bytes: size of the file.
        max_nodes: values once YAML aliases are expanded (a long text counts one per 64 chars).
        max_depth: levels of nesting (``{"a": [1]}`` is 2).
    """

    max_bytes: int
    max_nodes: int
    max_depth: int


CONFIG_LIMITS = Limits(max_bytes=1 << 20, max_nodes=200_000, max_depth=32)
"""A robot config: the Humanoid's is 10 kB, 400 values, 4 levels."""
SETTINGS_LIMITS = Limits(max_bytes=64 << 10, max_nodes=1_000, max_depth=8)
REQUEST_LIMITS = Limits(max_bytes=1 << 20, max_nodes=200_000, max_depth=32)
"""A request body or a WebSocket message (the servers bound their size before parsing)."""
_TEXT_CHARS_PER_NODE = 64


def _bad(source: str, reason: str) -> ConfigError:
    return ConfigError(f"{source}: {reason}", file=source, reason=reason)


def read_limited(path: str | os.PathLike[str], max_bytes: int, what: str = "file") -> bytes:
    """A regular file's bytes, refused past ``max_bytes``.

    Args:
        path: the file.
        max_bytes: the largest size accepted.
        what: what the file holds, for messages ("config", "move").

    Raises:
        ConfigError: missing, unreadable, not a regular file (a FIFO would block, a device never
            end), or too large.
    """
    source = str(path)
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK)  # a FIFO must not block the open
    except OSError as exc:
        raise _bad(source, f"cannot read the {what}: {exc.strerror or exc}") from None
    info = os.fstat(fd)
    if not stat.S_ISREG(info.st_mode):
        os.close(fd)
        kind = "a folder" if stat.S_ISDIR(info.st_mode) else "not a regular file"
        raise _bad(source, f"cannot read the {what}: it is {kind}")
    with os.fdopen(fd, "rb") as handle:
        if info.st_size > max_bytes:
            raise _bad(
                source, f"the {what} is {info.st_size:,} bytes; at most {max_bytes:,} are read"
            )
        try:
            data = handle.read(max_bytes + 1)
        except OSError as exc:
            raise _bad(source, f"cannot read the {what}: {exc.strerror or exc}") from None
    if len(data) > max_bytes:  # it grew while being read
        raise _bad(source, f"the {what} is over {max_bytes:,} bytes")
    return data


def _children(value: Any) -> Iterable[Any]:
    if isinstance(value, dict):
        return [*value.keys(), *value.values()]
    return value  # type: ignore[no-any-return]


def _weight(value: Any) -> int:
    if isinstance(value, str | bytes):
        return 1 + len(value) // _TEXT_CHARS_PER_NODE
    return 1


def check_shape(data: Any, source: str, limits: Limits) -> None:
    """Refuse a document nested too deeply, too large once aliases are expanded, or cyclic.

    Shared values (YAML aliases) are measured once and counted each time they are used, so
    the check takes time in the size of the text, not of the expansion; nothing recurses.

    Raises:
        ConfigError: one line saying which limit was passed.
    """
    sizes: dict[int, tuple[int, int]] = {}  # id -> (expanded nodes, depth)
    open_ids: set[int] = set()
    keep: list[Any] = []  # keeps the ids of measured containers valid
    stack: list[tuple[Any, bool]] = [(data, False)]
    while stack:
        value, finished = stack.pop()
        if not isinstance(value, dict | list | tuple):
            continue
        key = id(value)
        if finished:
            nodes, depth = 1, 1
            for child in _children(value):
                size = sizes.get(id(child)) if isinstance(child, dict | list | tuple) else None
                nodes += size[0] if size else _weight(child)
                depth = max(depth, 1 + size[1]) if size else depth
            open_ids.discard(key)
            sizes[key] = (nodes, depth)
            keep.append(value)
            if depth > limits.max_depth:
                raise _bad(source, f"nested more than {limits.max_depth} levels deep")
            if nodes > limits.max_nodes:
                raise _bad(
                    source, f"more than {limits.max_nodes:,} values once YAML aliases are expanded"
                )
            continue
        if key in sizes:
            continue
        if key in open_ids:
            raise _bad(source, "a YAML alias refers to a value that contains it (a cycle)")
        open_ids.add(key)
        stack.append((value, True))
        stack.extend((child, False) for child in _children(value))
        if len(open_ids) > limits.max_depth:
            raise _bad(source, f"nested more than {limits.max_depth} levels deep")


def parse_json(text: str | bytes, source: str, limits: Limits, *, check: bool = True) -> Any:
    """Parse a JSON document and check its shape.

    JSON has no aliases, so its size follows the text's: ``check=False`` skips the walk for
    large documents whose reader checks what it takes (a move's frames).

    Raises:
        ConfigError: a syntax error (with line and column), a number too long, a document
            nested too deeply or too large.
    """
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise _bad(
            source, f"JSON syntax error at line {exc.lineno}, column {exc.colno}: {exc.msg}"
        ) from None
    except RecursionError:
        raise _bad(source, f"nested more than {limits.max_depth} levels deep") from None
    except UnicodeDecodeError as exc:
        raise _bad(source, f"not valid JSON: {_first_line(exc)}") from None
    except ValueError:  # int() of more digits than sys.get_int_max_str_digits()
        raise _bad(source, "not valid JSON: it holds a number with too many digits") from None
    if check:
        check_shape(data, source, limits)
    return data


_OPENS = (
    yaml.BlockMappingStartToken,
    yaml.BlockSequenceStartToken,
    yaml.FlowMappingStartToken,
    yaml.FlowSequenceStartToken,
)
_CLOSES = (yaml.BlockEndToken, yaml.FlowMappingEndToken, yaml.FlowSequenceEndToken)


def _check_yaml_depth(text: str | bytes, source: str, limits: Limits) -> None:
    """Refuse deep YAML from its tokens (the scanner is a loop; the parser would recurse)."""
    depth = 0
    for token in yaml.scan(text, Loader=yaml.SafeLoader):
        if isinstance(token, _OPENS):
            depth += 1
            if depth > limits.max_depth + 1:  # +1: a block mapping wraps the whole document
                raise _bad(source, f"nested more than {limits.max_depth} levels deep")
        elif isinstance(token, _CLOSES):
            depth -= 1


# Documents up to this size are parsed once per text: a robot's build reads the same profiles
# again (every profile's header to find one, then its config), and the pure-Python scanner and
# the depth check take tens of milliseconds each, more on a busy machine. A copy is returned.
_CACHED_MAX_BYTES = 64 * 1024
_cache: dict[tuple[str | bytes, str, Limits], Any] = {}
_CACHE_SIZE = 64
_cache_lock = threading.Lock()
_MISSING = object()


def parse_yaml(text: str | bytes, source: str, limits: Limits) -> Any:
    """Parse a YAML document (safe tags only) and check its shape.

    Raises:
        ConfigError: a syntax error (with line and column), a number too long, a document
            nested too deeply, too large once aliases are expanded, or cyclic.
    """
    if len(text) > _CACHED_MAX_BYTES:
        return _parse_yaml(text, source, limits)
    key = (text, source, limits)
    with _cache_lock:
        data = _cache.get(key, _MISSING)
    if data is _MISSING:
        data = _parse_yaml(text, source, limits)
        with _cache_lock:
            if len(_cache) >= _CACHE_SIZE:
                _cache.pop(next(iter(_cache)))
            _cache[key] = data
    return copy.deepcopy(data)


def _parse_yaml(text: str | bytes, source: str, limits: Limits) -> Any:
    try:
        _check_yaml_depth(text, source, limits)
        data = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""
        problem = getattr(exc, "problem", None) or _first_line(exc)
        raise _bad(source, f"YAML syntax error{where}: {problem}") from None
    except RecursionError:
        raise _bad(source, f"nested more than {limits.max_depth} levels deep") from None
    except (ValueError, TypeError, UnicodeDecodeError) as exc:
        raise _bad(source, f"not valid YAML: {_first_line(exc)}") from None
    check_shape(data, source, limits)
    return data


def _first_line(exc: BaseException) -> str:
    text = str(exc)
    return text.splitlines()[0] if text else type(exc).__name__
