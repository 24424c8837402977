"""Register values as pypot's clients write them, read into the type each register takes.

pypot's Snap! server read a URL value with ``ast.literal_eval`` and its REST server set the JSON
body as it came: a boolean register took ``1``/``0`` (pypot's own Snap! block "set motor(s)
compliant/stiff" sends ``compliant:1``), ``True``/``False``, and a number could come as text
(``"30"``). These spellings are read here, literally (nothing is evaluated), before the
register's check (``values.check_write``); the v1 API keeps its strict JSON types.
Non-finite numbers (``nan``, ``inf``, ``1e309``) are refused by ``poppy_core.checks``.
"""

from __future__ import annotations

import math
import re
from typing import Any

from poppy_core import checks
from poppy_core.errors import ArgumentError

BOOLEANS = frozenset({"compliant", "safe_compliant"})
"""Registers holding true or false."""

NUMBERS = frozenset({"goal_position", "goal_speed", "moving_speed", "torque_limit", "max_torque"})
"""Registers holding one number."""

NUMBER_LISTS = frozenset({"pid", "angle_limit", "compliance_margin", "compliance_slope"})
"""Registers holding a number or a list of numbers."""

TRUE_WORDS = {"true": True, "false": False, "1": True, "0": False}
NUMBER_TEXT = re.compile(r"^[+-]?(\d+(\.\d*)?|\.\d+)([eE][+-]?\d+)?$")
NON_FINITE_TEXT = re.compile(r"^[+-]?(nan|inf|infinity)$", re.IGNORECASE)


def pypot_value(motor: str, register: str, value: Any) -> Any:
    """``value`` as register ``register`` of ``motor`` takes it, from a pypot client's spelling.

    Raises:
        ArgumentError: a non-finite or huge number, or a boolean register given something
            else than true/false/1/0 (a 400 on every server).
    """
    field = f"{motor}.{register}"
    if register in BOOLEANS:
        return _boolean(value, field)
    if register in NUMBERS:
        return _number(value, field)
    if register in NUMBER_LISTS:
        if isinstance(value, list | tuple):
            return [_number(item, field) for item in value]
        return _number(value, field)
    return value


def _boolean(value: Any, field: str) -> bool:
    if isinstance(value, bool):
        return value
    if isinstance(value, int | float) and value in (0, 1):
        return bool(value)
    if isinstance(value, str) and value.strip().lower() in TRUE_WORDS:
        return TRUE_WORDS[value.strip().lower()]
    shown = repr(value)[:40]
    raise ArgumentError(
        f"{field} must be true or false (or 1 or 0), got {shown}", field=field, value=value
    )


def _number(value: Any, field: str) -> Any:
    """A number given as a number or as text; anything else is left to the register's check."""
    if isinstance(value, str):
        text = value.strip()
        if NON_FINITE_TEXT.match(text):
            return checks.number(float(text), field)
        if not NUMBER_TEXT.match(text):
            return value  # the register's check names what it expected
        number = float(text)
        if math.isfinite(number) and number.is_integer() and not any(c in text for c in ".eE"):
            return int(text) if abs(number) < 2**53 else checks.number(number, field)
        value = number
    if isinstance(value, float | int) and not isinstance(value, bool):
        checks.number(value, field)  # refuses nan, inf, 1e309 and 400-digit integers
    return value
