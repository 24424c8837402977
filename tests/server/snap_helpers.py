"""Helpers of the Snap! tests: a served creature, polling for the robot's state."""

from __future__ import annotations

import time
from collections.abc import Callable


def wait_until(check: Callable[[], bool], timeout_s: float = 15.0) -> bool:
    """Poll ``check`` until true or ``timeout_s`` (generous: the machine may be loaded)."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if check():
            return True
        time.sleep(0.02)
    return check()


def near(value: float, target: float, tolerance: float = 2.0) -> bool:
    """``value`` within ``tolerance`` degrees of ``target``."""
    return abs(value - target) <= tolerance
