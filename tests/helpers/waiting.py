"""Waiting for something a background thread does, without timed assertions."""

from __future__ import annotations

import time
from collections.abc import Callable


def eventually(check: Callable[[], bool], timeout_s: float = 3.0, interval_s: float = 0.01) -> bool:
    """Poll ``check`` until it holds (True) or ``timeout_s`` runs out (False, after a last look).

    A loaded machine makes background threads late, never wrong: tests wait for the state they
    expect with a generous timeout instead of sleeping a fixed time.
    """
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if check():
            return True
        time.sleep(interval_s)
    return check()
