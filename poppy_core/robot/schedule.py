"""Drift-free periodic deadlines and a measured-rate meter for the background loops."""

from __future__ import annotations

import math
from collections import deque


class Periodic:
    """Deadlines at ``start + k * period``: late runs skip the periods they missed, no drift.

    With ``catch_up=1`` a run that ended late keeps the one deadline it overran (the next run
    starts at once): a loop whose runs take about its period on average, a few longer, keeps
    its rate; only periods missed by more than that are skipped.

    Attributes:
        period_s: time between deadlines.
        next_deadline: when the next run is due (same clock as the times passed in).
        missed: periods skipped because a run came too late.
    """

    def __init__(self, period_s: float, start_s: float, catch_up: int = 0) -> None:
        """Create a schedule whose first deadline is ``start_s``.

        Raises:
            ValueError: a period that is not a positive number.
        """
        if not period_s > 0 or not math.isfinite(period_s):
            raise ValueError(f"period must be a positive number of seconds, got {period_s}")
        self.period_s = period_s
        self.next_deadline = start_s
        self.missed = 0
        self.catch_up = catch_up

    def due(self, now_s: float) -> bool:
        """True when the deadline has come."""
        return now_s >= self.next_deadline

    def advance(self, now_s: float) -> int:
        """Move to the next deadline after a run that started at ``now_s``.

        Returns:
            How many whole periods were skipped (also added to ``missed``).
        """
        self.next_deadline += self.period_s
        skipped = 0
        kept = self.catch_up * self.period_s  # overdue deadlines still run
        if now_s >= self.next_deadline + kept:
            skipped = math.floor((now_s - self.next_deadline - kept) / self.period_s) + 1
            self.next_deadline += skipped * self.period_s
        self.missed += skipped
        return skipped


class RateMeter:
    """Measures how often something runs, over its last ``window`` runs."""

    def __init__(self, window: int = 50) -> None:
        self._times: deque[float] = deque(maxlen=max(2, window))
        self.count = 0

    def tick(self, now_s: float) -> None:
        """Record one run at ``now_s``."""
        self._times.append(now_s)
        self.count += 1

    def rate_at(self, now_s: float, stale_after_s: float) -> float:
        """``rate_hz``, or 0 when the last run is more than ``stale_after_s`` before ``now_s``."""
        if not self._times or now_s - self._times[-1] > stale_after_s:
            return 0.0
        return self.rate_hz

    @property
    def rate_hz(self) -> float:
        """Runs per second over the window (0 until two runs were seen)."""
        if len(self._times) < 2:
            return 0.0
        span = self._times[-1] - self._times[0]
        return (len(self._times) - 1) / span if span > 0 else 0.0
