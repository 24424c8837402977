"""Shared start times: the robots of a fleet command start together, armed then fired.

A start with a ``start_at`` (wall clock; an explicit argument of the service's operations:
``RobotService.control_primitive``, ``MoveService.play``, ``RobotService.follow``) does all its
work on arrival: the move is loaded and checked, the player or primitive and its thread are
made; that thread then waits at a ``Gate`` (``StartTimes.gate``), and the request is answered
(a refusal too: the checks ran on arrival). At ``start_at`` one thread per start time and
service, woken by a precise wait (a sleep to ``SPIN_S`` before, then one for the rest, so that a
long sleep's drift is made up), opens every gate due: the start itself is only a thread
released. Nothing else wakes then (the replies went out on arrival), so the robots of one process
fire within a fraction of a millisecond of each other and of ``start_at`` on an idle machine. A
stop before ``start_at`` cancels the gate and nothing starts.
"""

from __future__ import annotations

import threading
import time
from typing import Any

from poppy_core import checks
from poppy_core.schedule import Gate

MAX_START_DELAY_S = 60.0
"""How far from now a ``start_at`` may be (a clock that far off is refused, not waited)."""

SPIN_S = 0.002
"""How long before the start time the firing thread's first sleep ends; the rest is slept again
from a fresh reading of the clock. Not a spin nor short steps: each wake-up of a thread has to
take the GIL back, which on a busy process can wait for another thread's switch interval."""


def check_start_at(value: Any) -> float | None:
    """``start_at`` (``time.time()`` seconds) checked as its delay from now: the one rule of
    every surface that takes one (REST v1, Zenoh, ROS 2's ``header.stamp``).

    Raises:
        ArgumentError: not a number, or more than ``MAX_START_DELAY_S`` from now either way.
    """
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, int | float):
        checks.number(value, "start_at")  # raises, naming the field
    now = time.time()
    delay = checks.in_range(
        float(value) - now, -MAX_START_DELAY_S, MAX_START_DELAY_S, "start_at (from now)", "s"
    )
    return now + delay


def late_by(start_at: float) -> float:
    """How long ago ``start_at`` was, in seconds to the millisecond (0: still ahead). A start
    that comes after its time runs at once (a fleet on a slow network still plays, a little
    behind) and its answer says by how much."""
    return max(0.0, round(time.time() - start_at, 3))


def on_monotonic(start_at: float) -> float:
    """Wall-clock ``start_at`` on the ``time.monotonic()`` clock (the motion's)."""
    return time.monotonic() + (start_at - time.time())


def wait_until(when: float) -> None:
    """Return at wall-clock ``when`` (never before), a fraction of a millisecond late on an idle
    machine: one sleep to ``SPIN_S`` before, then one for the rest."""
    while True:
        left = when - time.time()
        if left <= 0:
            return
        time.sleep(left - SPIN_S if left > SPIN_S else left)


class StartTimes:
    """The gates armed for start times, one firing thread per start time (a service's)."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._due: dict[float, list[Gate]] = {}

    def gate(self, start_at: float | None) -> Gate | None:
        """The gate an armed start waits at, or None: start at once (no ``start_at``, or one
        already past). The gate opens at ``start_at``; cancel it to call the start off."""
        if start_at is None or start_at <= time.time():
            return None
        gate = Gate(at=on_monotonic(start_at))  # the start, on the motion's clock
        with self._lock:
            gates = self._due.get(start_at)
            first = gates is None
            if gates is None:
                gates = self._due[start_at] = []
            gates.append(gate)
        if first:
            threading.Thread(
                target=self._fire, args=(start_at,), name="fleet-start", daemon=True
            ).start()
        return gate

    @property
    def armed(self) -> int:
        """Gates waiting for their start time."""
        with self._lock:
            return sum(len(gates) for gates in self._due.values())

    def _fire(self, when: float) -> None:
        wait_until(when)
        with self._lock:
            gates = self._due.pop(when, [])
        for gate in gates:
            gate.open()
