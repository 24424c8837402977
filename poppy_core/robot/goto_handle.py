"""``GotoHandle``: a running goto one can wait on (what ``GotoRunner.start`` returns)."""

from __future__ import annotations

import threading


class GotoHandle:
    """A running goto of one or several motors; done when every motor arrived or was cancelled."""

    def __init__(self, count: int, duration_s: float) -> None:
        self._left = count
        self._done = threading.Event()
        self.duration_s = duration_s
        self.cancelled = False
        if count == 0:
            self._done.set()

    @property
    def done(self) -> bool:
        """True once the motion is over (or cancelled)."""
        return self._done.is_set()

    def wait(self, timeout_s: float | None = None) -> bool:
        """Block until the motion is over; False when ``timeout_s`` ran out first."""
        return self._done.wait(timeout_s)

    def _finish_one(self, cancelled: bool) -> None:
        self.cancelled = self.cancelled or cancelled
        self._left -= 1
        if self._left <= 0:
            self._done.set()
