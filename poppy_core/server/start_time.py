"""A request's shared start time: the robots of a fleet command start together, armed then fired.

The Zenoh ``api`` queryable runs a request with ``start_at`` (wall clock) at once, with
``START_AT`` set. The actions that start something (a primitive, a move) do all their work on
arrival: the move is loaded and checked, the player or primitive and its thread are made; that
thread then waits at a ``Gate`` (``start_gate``), and the request is answered (a refusal too:
the checks ran on arrival). At ``start_at`` one thread per process, woken by a precise wait (a
sleep to ``SPIN_S`` before, then one for the rest, so that a long sleep's drift is made up),
opens every gate due: the start itself is only a thread released. Nothing else wakes then (the
replies went out on arrival), so the robots of one process fire within a fraction of a
millisecond of each other and of ``start_at`` on an idle machine. A stop before ``start_at``
cancels the gate and nothing starts.
"""

from __future__ import annotations

import threading
import time
from contextvars import ContextVar
from dataclasses import dataclass, field

from poppy_core.schedule import Gate

START_AT: ContextVar[float | None] = ContextVar("start_at", default=None)
"""The wall-clock time (``time.time()``) the current request's action starts at, or None."""

SPIN_S = 0.002
"""How long before the start time the firing thread's first sleep ends; the rest is slept again
from a fresh reading of the clock. Not a spin nor short steps: each wake-up of a thread has to
take the GIL back, which on a busy process can wait for another thread's switch interval."""


@dataclass
class _Due:
    gates: list[Gate] = field(default_factory=list)


_lock = threading.Lock()
_due: dict[float, _Due] = {}


def start_gate() -> Gate | None:
    """The gate an armed start of the current request waits at, or None: start at once (no
    ``START_AT``, or one already past). The gate opens at ``START_AT``; cancel it to call the
    start off."""
    when = START_AT.get()
    if when is None or when <= time.time():
        return None
    gate = Gate(at=time.monotonic() + (when - time.time()))  # the start, on the motion's clock
    with _lock:
        due = _due.get(when)
        first = due is None
        if due is None:
            due = _due[when] = _Due()
        due.gates.append(gate)
    if first:
        threading.Thread(target=_fire, args=(when, due), name="fleet-start", daemon=True).start()
    return gate


def wait_until(when: float) -> None:
    """Return at wall-clock ``when`` (never before), a fraction of a millisecond late on an idle
    machine: one sleep to ``SPIN_S`` before, then one for the rest."""
    while True:
        left = when - time.time()
        if left <= 0:
            return
        time.sleep(left - SPIN_S if left > SPIN_S else left)


def _fire(when: float, due: _Due) -> None:
    wait_until(when)
    with _lock:
        _due.pop(when, None)
        gates = list(due.gates)
    for gate in gates:
        gate.open()
