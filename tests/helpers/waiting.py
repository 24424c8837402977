"""Waiting for something a background thread does, without timed assertions."""

from __future__ import annotations

import time
from collections.abc import Callable

# A test's own timeout says how long the thing should take on an idle machine; a loaded one
# (the suite's parallel workers on 2 cores, CI) makes threads late, never wrong, so no wait gives
# up before this. Waiting longer costs nothing when the state comes: it is polled.
MIN_TIMEOUT_S = 15.0


def eventually(check: Callable[[], bool], timeout_s: float = 3.0, interval_s: float = 0.01) -> bool:
    """Poll ``check`` until it holds (True) or the timeout runs out (False, after a last look).

    The timeout is ``timeout_s``, but never less than ``MIN_TIMEOUT_S``: tests wait for the
    state they expect instead of sleeping a fixed time, and a wait is not a speed check (speed
    goals live in the benchmarks).
    """
    deadline = time.monotonic() + max(timeout_s, MIN_TIMEOUT_S)
    while time.monotonic() < deadline:
        if check():
            return True
        time.sleep(interval_s)
    return check()


def within(check: Callable[[], bool], timeout_s: float, interval_s: float = 0.005) -> bool:
    """Poll ``check`` for at most ``timeout_s`` (no floor): for the few waits whose window is
    what the test checks (a write heard before a held-back reply is due), or that may run out
    by design (a step that gives no sign it was taken). Any other wait is ``eventually``."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if check():
            return True
        time.sleep(interval_s)
    return check()
