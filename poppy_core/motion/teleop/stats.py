"""What a teleoperation reports: ``TeleopStatus`` (live) and ``TeleopReport`` (rate, timings)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any


@dataclass(frozen=True)
class TeleopStatus:
    """A snapshot of a running teleoperation (for displays).

    Attributes:
        state: the follower's state, or ``leader lost``.
        elapsed_s: time since the start.
        ticks: ticks run.
        measured_hz: ticks per second so far.
        holds: times the follower was held because the leader was lost.
        leader: the leader positions read last.
        targets: the follower targets sent last.
        follower: the follower positions last known.
        reason: why the state last changed.
    """

    state: str
    elapsed_s: float
    ticks: int
    measured_hz: float
    holds: int
    leader: dict[str, float]
    targets: dict[str, float]
    follower: dict[str, float]
    reason: str


@dataclass
class TeleopReport:
    """What a teleoperation did (``Teleoperation.report()``); times in seconds.

    ``read_s``: the leader read of each tick; ``pipeline_s``: leader read done → targets handed
    to the follower (for a local follower, written to its bus).
    """

    rate_hz: float
    duration_s: float
    ticks: int
    measured_hz: float
    missed_periods: int
    holds: int
    read_s: list[float] = field(default_factory=list)
    pipeline_s: list[float] = field(default_factory=list)
    record_path: str | None = None
    recorded_frames: int = 0

    def as_dict(self) -> dict[str, Any]:
        """Plain data with percentiles instead of the samples (for ``--json``)."""
        return {
            "rate_hz": self.rate_hz,
            "duration_s": round(self.duration_s, 3),
            "ticks": self.ticks,
            "measured_hz": round(self.measured_hz, 2),
            "missed_periods": self.missed_periods,
            "holds": self.holds,
            "read_ms": _percentiles_ms(self.read_s),
            "pipeline_ms": _percentiles_ms(self.pipeline_s),
            "record_path": self.record_path,
            "recorded_frames": self.recorded_frames,
        }


def _percentiles_ms(values: Sequence[float]) -> dict[str, float | None]:
    if not values:
        return {"p50": None, "p99": None, "max": None}
    ordered = sorted(values)

    def at(q: float) -> float:
        return round(ordered[min(len(ordered) - 1, int(q * (len(ordered) - 1) + 0.5))] * 1e3, 3)

    return {"p50": at(0.5), "p99": at(0.99), "max": round(ordered[-1] * 1e3, 3)}
