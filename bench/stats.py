"""Small statistics and formatting helpers shared by the benchmarks."""

from __future__ import annotations

import statistics
from collections.abc import Sequence


def summary(values: Sequence[float]) -> dict[str, float]:
    """Median, min and max of repeated measurements (all 0 when there is none)."""
    if not values:
        return {"median": 0.0, "min": 0.0, "max": 0.0, "n": 0}
    return {
        "median": statistics.median(values),
        "min": min(values),
        "max": max(values),
        "n": len(values),
    }


def fmt_s(value: float | None) -> str:
    """Seconds with a precision suited to their size (``-`` for None)."""
    if value is None:
        return "-"
    if value < 0.01:
        return f"{value * 1000:.2f} ms"
    if value < 1:
        return f"{value:.3f} s"
    return f"{value:.2f} s"


def fmt_range(stats: dict[str, float]) -> str:
    """``min – max`` of a summary."""
    return f"{fmt_s(stats['min'])} – {fmt_s(stats['max'])}"


def fmt_ratio(numerator: float | None, denominator: float | None) -> str:
    """``12.3×`` or ``-`` when either side is missing."""
    if numerator is None or denominator is None or denominator <= 0:
        return "-"
    ratio = numerator / denominator
    return f"{ratio:.0f}×" if ratio >= 100 else f"{ratio:.1f}×"
