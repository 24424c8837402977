"""Snap!'s plain text both ways: answers as pypot's Snap! server prints them, URL values read.

pypot's Snap! server (pypot 5.0.2, ``pypot/server/snap.py``) answers ``str()`` of Python values:
``True``/``False``, ``(4, 2, 0)`` for tuples, positions with at most two decimals (pypot's
conversions round there), lists joined with ``/`` (names) or ``;`` (values of several motors),
``Done!`` after a change. Values in URLs are Python literals for pypot (``False``, ``30``,
``(-90, 90)``); Snap! itself writes booleans as ``true``/``false``: both are read here.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable
from typing import Any

DONE = "Done!"
NAMES_SEP = "/"
VALUES_SEP = ";"
DECIMALS = 2
"""Floats are answered rounded to 2 decimals, as pypot's register conversions round them."""

NUMBER = re.compile(r"^[+-]?(\d+(\.\d*)?|\.\d+)([eE][+-]?\d+)?$")
LIST_SPLIT = re.compile(r"[;,\s]+")


def value_text(value: Any) -> str:
    """A value as pypot's Snap! server prints it (``str()`` of the Python value)."""
    if value is None or isinstance(value, bool | str):
        return str(value)
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return str(round(value, DECIMALS)) if math.isfinite(value) else "None"
    if isinstance(value, list | tuple):
        inner = ", ".join(value_text(v) if not isinstance(v, str) else repr(v) for v in value)
        return f"({inner},)" if len(value) == 1 else f"({inner})"
    if isinstance(value, dict):
        return str({k: value_text(v) for k, v in value.items()})
    return str(value)


def names_text(names: Iterable[str]) -> str:
    """Names joined as pypot's Snap! server joins them: ``m1/m2/m3``."""
    return NAMES_SEP.join(names)


def values_text(values: Iterable[Any]) -> str:
    """Values of several motors: ``0.0;-0.0;12.5``."""
    return VALUES_SEP.join(value_text(v) for v in values)


def number_text(value: float, decimals: int = 3) -> str:
    """A duration or a coordinate: ``1.12``, ``0.56``."""
    return str(round(value, decimals))


def split_names(text: str) -> list[str]:
    """``m1;m2``, ``m1 m2`` or ``m1,m2`` -> ``["m1", "m2"]`` (empty parts dropped)."""
    return [part for part in LIST_SPLIT.split(text.strip()) if part]


def parse_value(text: str) -> Any:
    """A URL value: booleans (``True``, ``true``), numbers, ``(a, b)``, ``[a, b]``, else text.

    Never evaluates anything: only these literal forms are read.
    """
    raw = text.strip()
    lowered = raw.lower()
    if lowered in ("true", "false"):
        return lowered == "true"
    if lowered in ("none", "null"):
        return None
    if NUMBER.match(raw):
        number = float(raw)
        if number.is_integer() and not any(c in raw for c in ".eE") and abs(number) < 2**53:
            return int(number)
        return number
    if len(raw) >= 2 and raw[0] + raw[-1] in ("()", "[]"):
        inner = raw[1:-1].strip().rstrip(",")
        return [parse_value(part) for part in inner.split(",")] if inner else []
    return raw
