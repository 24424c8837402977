"""Waiting for something a background thread does, without timed assertions; waits that grow
with the machine's measured load."""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from pathlib import Path

# A test's own timeout says how long the thing should take on an idle machine; a loaded one
# (the suite's parallel workers on 2 cores, CI) makes threads late, never wrong, so no wait gives
# up before this (times the load factor). Waiting longer costs nothing when the state comes: it
# is polled.
MIN_TIMEOUT_S = 15.0

# The load factor's bound: a machine this loaded is stuck, not busy, and a wait must end.
MAX_LOAD_FACTOR = 8.0

# The first-reply floor, on an idle machine, of a bus whose motors are an emulator thread (on a
# pty or TCP) that a busy machine runs tens of milliseconds late now and then: the product's own
# floor (10 ms) is a real adapter's. Times the load factor; it costs nothing while motors answer.
LOADED_REPLY_FLOOR_IDLE_S = 0.5
# The same for the `poppy` commands a test runs, through the product's POPPY_REPLY_FLOOR_S
# (poppy_core.bus.timing.REPLY_FLOOR_ENV). Lower: some commands look for motors that are absent
# on purpose (`doctor` on a one-motor kit waits the floor three times for each missing one).
COMMAND_REPLY_FLOOR_IDLE_S = 0.2
REPLY_FLOOR_ENV = "POPPY_REPLY_FLOOR_S"


def runnable_now() -> int:
    """Threads running or ready to run right now (``/proc/loadavg``'s 4th field), 0 if unknown.

    The load averages lag: the 1-minute one takes a minute to see busy loops started beside the
    suite; this count sees them at once."""
    try:
        field = Path("/proc/loadavg").read_text().split()[3]
        return max(0, int(field.split("/")[0]) - 1)  # less the reader itself
    except (OSError, IndexError, ValueError):
        return 0


def load_factor() -> float:
    """How many times slower than an idle machine a thread may be served now: the load (the
    1-minute average or the threads ready now, whichever is higher) per core, at least 1, at most
    ``MAX_LOAD_FACTOR``. Measured at each call (a few microseconds)."""
    try:
        average = os.getloadavg()[0]
    except OSError:
        average = 0.0
    cores = os.cpu_count() or 1
    return min(MAX_LOAD_FACTOR, max(1.0, max(average, float(runnable_now())) / cores))


def scaled(seconds: float) -> float:
    """``seconds`` (enough on an idle machine) times the load factor: a deadline that must be met
    by a thread of the test process or of the emulator it serves."""
    return seconds * load_factor()


def http_timeout(idle_s: float = 10.0) -> float:
    """The timeout of an HTTP client of a test (``httpx.Client(timeout=http_timeout())``):
    ``idle_s``, enough for an answer of a server the test runs on an idle machine, times the load
    factor measured now. httpx's own default (5 s) is a fixed deadline a busy machine misses."""
    return scaled(idle_s)


def reply_floor_env() -> dict[str, str]:
    """The environment that gives a `poppy` command run by a test (in this process or another)
    the loaded first-reply floor, scaled by the load measured now: its motors are an emulator
    of the test (a thread, or a `poppy emulate` process) that a busy machine runs late."""
    return {REPLY_FLOOR_ENV: f"{scaled(COMMAND_REPLY_FLOOR_IDLE_S):.3f}"}


def eventually(check: Callable[[], bool], timeout_s: float = 3.0, interval_s: float = 0.01) -> bool:
    """Poll ``check`` until it holds (True) or the timeout runs out (False, after a last look).

    The timeout is ``timeout_s``, but never less than ``MIN_TIMEOUT_S``, times the load factor
    (measured when the wait starts): tests wait for the state they expect instead of sleeping a
    fixed time, and a wait is not a speed check (speed goals live in the benchmarks).
    """
    deadline = time.monotonic() + scaled(max(timeout_s, MIN_TIMEOUT_S))
    while time.monotonic() < deadline:
        if check():
            return True
        time.sleep(interval_s)
    return check()


def within(check: Callable[[], bool], timeout_s: float, interval_s: float = 0.005) -> bool:
    """Poll ``check`` for at most ``timeout_s`` (no floor, no load factor): for the few waits
    whose window is what the test checks (a write heard before a held-back reply is due), or that
    may run out by design (a step that gives no sign it was taken). Any other wait is
    ``eventually``."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if check():
            return True
        time.sleep(interval_s)
    return check()
