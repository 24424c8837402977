"""Helpers of the Snap! tests: a served creature, polling for the robot's state."""

from __future__ import annotations

from tests.helpers.waiting import eventually as wait_until

__all__ = ["near", "wait_until"]


def near(value: float, target: float, tolerance: float = 2.0) -> bool:
    """``value`` within ``tolerance`` degrees of ``target``."""
    return abs(value - target) <= tolerance
