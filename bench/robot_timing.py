"""Loop timing from start times: achieved rate, rate error and period jitter (p99, max)."""

from __future__ import annotations

import itertools
import math
import statistics
from collections.abc import Sequence
from typing import Any

MIN_RUNS = 3


def percentile(values: Sequence[float], pct: float) -> float:
    """The nearest-rank percentile of ``values`` (0 when empty).

    Args:
        values: the sample, in any order.
        pct: 0 < pct <= 100.

    Returns:
        The smallest value with at least ``pct`` % of the sample at or below it.
    """
    if not values:
        return 0.0
    ordered = sorted(values)
    rank = max(1, math.ceil(pct / 100.0 * len(ordered)))
    return ordered[min(rank, len(ordered)) - 1]


def loop_timing(starts_s: Sequence[float], target_hz: float | None) -> dict[str, Any]:
    """Rate and jitter of a loop from the times its runs started.

    Jitter is how far each period (start to next start) is from the reference period:
    ``1 / target_hz`` when a target is given (the loop should keep it), else the median period
    (a loop running as fast as it can has no target to keep).

    Args:
        starts_s: start times in seconds, increasing.
        target_hz: the rate asked for, or None.

    Returns:
        ``runs``, ``rate_hz`` (runs per second over the window), ``error_pct`` (distance of
        the rate from the target, None without one), ``period_ms`` (median),
        ``jitter_p99_ms``, ``jitter_max_ms``, and ``error`` (None, or why nothing was computed).
    """
    if len(starts_s) < MIN_RUNS:
        return {"runs": len(starts_s), "error": f"only {len(starts_s)} loop runs recorded"}
    periods = [b - a for a, b in itertools.pairwise(starts_s)]
    span = starts_s[-1] - starts_s[0]
    if span <= 0:
        return {"runs": len(starts_s), "error": "start times do not increase"}
    rate_hz = len(periods) / span
    reference = 1.0 / target_hz if target_hz else statistics.median(periods)
    deviations = [abs(p - reference) for p in periods]
    return {
        "runs": len(starts_s),
        "rate_hz": rate_hz,
        "error_pct": abs(rate_hz - target_hz) / target_hz * 100.0 if target_hz else None,
        "period_ms": statistics.median(periods) * 1000.0,
        "jitter_p99_ms": percentile(deviations, 99.0) * 1000.0,
        "jitter_max_ms": max(deviations) * 1000.0,
        "error": None,
    }
