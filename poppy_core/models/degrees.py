"""Degrees as people read them: as many decimals as the motor's resolution needs, never ``-0``."""

from __future__ import annotations

import math

from poppy_core.models.converters import Linear
from poppy_core.models.model import ServoModel

DEFAULT_TICK_DEG = 0.1
"""The step assumed when the motor is not known: one decimal."""


def tick_deg(model: ServoModel) -> float:
    """One position tick of ``model`` in degrees (XL-320/AX 300°/1024 ≈ 0.29°, MX 360°/4096)."""
    conversion = model.register("goal_position").conversion
    return abs(conversion.scale) if isinstance(conversion, Linear) else DEFAULT_TICK_DEG


def decimals(step_deg: float) -> int:
    """The decimals that tell two neighbouring ticks of ``step_deg`` apart (0.29° -> 1)."""
    if step_deg <= 0 or not math.isfinite(step_deg):
        return 1
    return max(0, math.ceil(-math.log10(step_deg) - 1e-9))


def fmt_deg(value: float, step_deg: float = DEFAULT_TICK_DEG, unit: str = "°") -> str:
    """``value`` rounded to the decimals of ``step_deg``, with ``unit``; ``-0`` shows as ``0``."""
    places = decimals(step_deg)
    text = f"{round(value, places) + 0.0:.{places}f}"
    if float(text) == 0:
        text = text.lstrip("-")
    return f"{text}{unit}"
