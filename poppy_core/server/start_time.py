"""A request's shared start time: the robots of a fleet command start together.

The Zenoh ``api`` queryable runs a request with ``start_at`` (wall clock) at once, with
``START_AT`` set; the actions that start something (a primitive, a move) go through
``start_at_time``, so the request is parsed, checked and routed ahead of time and only the
start itself waits for the clock. Every start due at one time in a process is run by one
thread, one after the other: one thread wakes for them all (robots served together in one
process would otherwise wake as many threads at once, each waiting for the others).
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from contextvars import ContextVar
from typing import TypeVar

START_AT: ContextVar[float | None] = ContextVar("start_at", default=None)
"""The wall-clock time (``time.time()``) the current request's action starts at, or None."""

T = TypeVar("T")
_lock = threading.Lock()
_due: dict[float, list[Callable[[], None]]] = {}


def start_at_time(start: Callable[[], T]) -> T:
    """``start()`` now, or at the current request's ``START_AT`` (its result, its error)."""
    when = START_AT.get()
    if when is None or when <= time.time():
        return start()
    done = threading.Event()
    outcome: list[T] = []
    failure: list[BaseException] = []

    def run() -> None:
        try:
            outcome.append(start())
        except BaseException as exc:  # handed back to the request's thread
            failure.append(exc)
        finally:
            done.set()

    with _lock:
        first = when not in _due
        _due.setdefault(when, []).append(run)
    if first:
        threading.Thread(target=_starter, args=(when,), name="fleet-start", daemon=True).start()
    done.wait()
    if failure:
        raise failure[0]
    return outcome[0]


def _starter(when: float) -> None:
    delay = when - time.time()
    if delay > 0:
        time.sleep(delay)
    with _lock:
        due = _due.pop(when, [])
    for run in due:
        run()
