"""Typed values of primitive properties: text from a command line or JSON, checked and converted."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

from poppy_core import checks
from poppy_core.errors import ArgumentError

_TRUE = ("1", "true", "yes", "on")
_FALSE = ("0", "false", "no", "off")


def convert_value(name: str, current: Any, value: Any) -> Any:
    """``value`` converted to the type of ``current`` (text from a command line is parsed).

    Raises:
        ArgumentError: the value does not fit.
    """

    def bad(reason: str) -> ArgumentError:
        return ArgumentError(f"property {name}: {reason}", field=name, value=value)

    if current is None:
        return value
    if isinstance(current, bool):
        if isinstance(value, bool):
            return value
        text = str(value).strip().lower()
        if text in _TRUE or text in _FALSE:
            return text in _TRUE
        raise bad(f"{value!r} is not true or false")
    if isinstance(current, int | float):
        if isinstance(value, bool):
            raise bad(f"{value!r} is not a number")
        try:
            number = float(value) if isinstance(current, float) else int(value)
        except (TypeError, ValueError):
            kind = "a number" if isinstance(current, float) else "an integer"
            raise bad(f"{value!r} is not {kind}") from None
        try:
            checks.number(number, name)  # finite, and small enough for any arithmetic
        except ArgumentError as exc:
            raise bad(str(exc)) from None
        return number
    if isinstance(current, str):
        return str(value)
    if isinstance(current, list | tuple):
        items = value.split(",") if isinstance(value, str) else value
        if not isinstance(items, Sequence):
            raise bad(f"{value!r} is not a list")
        return [str(item).strip() for item in items if str(item).strip()]
    if isinstance(current, dict):
        return _mapping(value, bad)
    raise bad(f"cannot set a {type(current).__name__} from {value!r}")


def _mapping(value: Any, bad: Callable[[str], ArgumentError]) -> dict[str, float]:
    """``{"m1": 10}`` or the text ``"m1=10,m2=-5"`` as a name -> number mapping."""
    if isinstance(value, str):
        pairs = [item.partition("=") for item in value.split(",") if item.strip()]
        if any(not sep for _, sep, _ in pairs):
            raise bad(f"{value!r} is not NAME=NUMBER,NAME=NUMBER")
        value = {key.strip(): text for key, _, text in pairs}
    if not isinstance(value, dict):
        raise bad(f"{value!r} is not a mapping")
    out: dict[str, float] = {}
    for key, item in value.items():
        try:
            number = float(item)
        except (TypeError, ValueError):
            raise bad(f"{key}: {item!r} is not a number") from None
        if not math.isfinite(number):
            raise bad(f"{key}: the value must be finite")
        out[str(key)] = number
    return out
