"""A request's shared start time: the robots of a fleet command start together.

The Zenoh ``api`` queryable runs a request with ``start_at`` (wall clock) at once, with
``START_AT`` set; the actions that start something (a primitive, a move) call ``wait_for_start``
in their worker thread just before starting, so the request is parsed, checked and routed ahead
of time and only the start itself waits for the clock.
"""

from __future__ import annotations

import time
from contextvars import ContextVar

START_AT: ContextVar[float | None] = ContextVar("start_at", default=None)
"""The wall-clock time (``time.time()``) the current request's action starts at, or None."""


def wait_for_start() -> None:
    """Sleep until the current request's ``START_AT`` (at once without one, or once past)."""
    when = START_AT.get()
    if when is None:
        return
    delay = when - time.time()
    if delay > 0:
        time.sleep(delay)
