"""One-line ConfigError messages: field paths, value display, pydantic error translation."""

from __future__ import annotations

import json
import re
from collections.abc import Sequence
from typing import Any

from pydantic import ValidationError

from poppy_core.errors import ConfigError

DEFAULT_SOURCE = "<config>"
_MAX_VALUE_CHARS = 80

# pydantic's wording ("Input should be ...") rephrased for a config file reader.
_REWORDS: tuple[tuple[str, str], ...] = (
    (r"^Input should be ", "must be "),
    (r"^Field required$", "missing (required)"),
    (r"^Value error, ", ""),
)


def _plain(value: Any) -> Any:
    """Turn tuples into lists and integral floats into ints, for compact display."""
    if isinstance(value, float) and value.is_integer() and abs(value) < 1e15:
        return int(value)
    if isinstance(value, (list, tuple)):
        return [_plain(item) for item in value]
    if isinstance(value, dict):
        return {str(key): _plain(item) for key, item in value.items()}
    return value


def show(value: Any) -> str:
    """Render a config value the way it would read in the file (JSON-like, one line).

    Args:
        value: Any value taken from (or destined to) a config.

    Returns:
        A one-line rendering, shortened with "..." past 80 characters.
    """
    try:
        text = json.dumps(_plain(value), ensure_ascii=False, separators=(", ", ": "))
    except (TypeError, ValueError):
        text = repr(value)
    text = " ".join(text.split())
    if len(text) > _MAX_VALUE_CHARS:
        text = text[: _MAX_VALUE_CHARS - 3] + "..."
    return text


def join_path(loc: Sequence[str | int]) -> str:
    """Join a location into a field path, e.g. ``motors.m3.angle_limit[1]``.

    Args:
        loc: Keys (str) and list indices (int), outermost first.

    Returns:
        The dotted path; list indices are written in brackets.
    """
    path = ""
    for part in loc:
        if isinstance(part, int):
            path += f"[{part}]"
        else:
            path += f".{part}" if path else str(part)
    return path


def config_error(
    source: str, field: str, value: Any, reason: str, *, show_value: bool = True
) -> ConfigError:
    """Build a ConfigError with the one-line message ``source: field = value: reason``.

    Args:
        source: The file name (or a label such as "<config>").
        field: The dotted field path; empty for the whole document (``source: reason``).
        value: The offending value.
        reason: Why it is wrong.
        show_value: Whether to print ``= value`` (not for missing fields).

    Returns:
        The error, ready to raise.
    """
    if not field:
        got = f" (got {show(value)})" if show_value else ""
        message = f"{source}: {reason}{got}"
    elif show_value:
        message = f"{source}: {field} = {show(value)}: {reason}"
    else:
        message = f"{source}: {field}: {reason}"
    return ConfigError(message, file=source, field=field, value=value, reason=reason)


def _reword(message: str) -> str:
    for pattern, replacement in _REWORDS:
        message = re.sub(pattern, replacement, message)
    return message


def validation_problems(exc: ValidationError, source: str) -> list[ConfigError]:
    """Every error of a pydantic ValidationError as one-line ConfigErrors, in document order.

    Args:
        exc: The pydantic error.
        source: The file name (or label) to put first in each message.

    Returns:
        One ConfigError per problem (the same field and reason only once), each naming the field
        path, the bad value and why.
    """
    problems: list[ConfigError] = []
    seen: set[tuple[str, str]] = set()
    for error in exc.errors(include_url=False):
        problem = _translate(error, source)
        key = (problem.field or "", problem.reason or "")
        if key not in seen:
            seen.add(key)
            problems.append(problem)
    return problems


def from_validation_error(exc: ValidationError, source: str) -> ConfigError:
    """Translate a pydantic ValidationError into a ConfigError listing every problem.

    Args:
        exc: The pydantic error.
        source: The file name (or label) to put first in the message.

    Returns:
        The first problem, with ``problems`` holding all of them.
    """
    return ConfigError.of_problems(validation_problems(exc, source))


def _translate(error: Any, source: str) -> ConfigError:
    raw_loc = list(error["loc"])
    reason = _reword(str(error["msg"]))
    # Dict-key errors end with a "[key]" marker after the key itself, which is the bad value.
    if "[key]" in raw_loc:
        at = raw_loc.index("[key]")
        raw_loc = [*raw_loc[: at - 1], str(raw_loc[at - 1])]
        reason = f"name {reason}"
    loc: list[str | int] = raw_loc
    if error["type"] == "missing":
        return config_error(source, join_path(loc), None, reason, show_value=False)
    return config_error(source, join_path(loc), error["input"], reason)
