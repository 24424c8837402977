"""Pacing a loop: drift-free deadlines, a rate meter, a doubling backoff, the guard that keeps a
loop through raising ticks, and ``Ticker``, the one periodic loop body."""

from __future__ import annotations

import logging
import math
import threading
import time
from collections import deque
from collections.abc import Callable

from poppy_core import checks
from poppy_core.errors import ArgumentError, PoppyError

logger = logging.getLogger(__name__)


class Periodic:
    """Deadlines at ``start + k * period``: late runs skip the periods they missed, no drift.

    With ``catch_up=1`` a run that ended late keeps the one deadline it overran (the next run
    starts at once): a loop whose runs take about its period on average, a few longer, keeps
    its rate; only periods missed by more than that are skipped.

    Attributes:
        period_s: time between deadlines.
        next_deadline: when the next run is due (same clock as the times passed in).
        missed: periods skipped because a run came too late.
    """

    def __init__(self, period_s: float, start_s: float, catch_up: int = 0) -> None:
        """Create a schedule whose first deadline is ``start_s``.

        Raises:
            ArgumentError: a period outside ``checks.period`` (a ``ValueError`` too).
        """
        self.period_s = checks.period(period_s)
        self.next_deadline = start_s
        self.missed = 0
        self.catch_up = catch_up

    def due(self, now_s: float) -> bool:
        """True when the deadline has come."""
        return now_s >= self.next_deadline

    def advance(self, now_s: float) -> int:
        """Move to the next deadline after a run that started at ``now_s``.

        Returns:
            How many whole periods were skipped (also added to ``missed``).
        """
        self.next_deadline += self.period_s
        skipped = 0
        kept = self.catch_up * self.period_s  # overdue deadlines still run
        if now_s >= self.next_deadline + kept:
            skipped = math.floor((now_s - self.next_deadline - kept) / self.period_s) + 1
            self.next_deadline += skipped * self.period_s
        self.missed += skipped
        return skipped


class RateMeter:
    """Measures how often something runs, over its last ``window`` runs."""

    def __init__(self, window: int = 50) -> None:
        self._times: deque[float] = deque(maxlen=max(2, window))
        self.count = 0

    def tick(self, now_s: float) -> None:
        """Record one run at ``now_s``."""
        self._times.append(now_s)
        self.count += 1

    def rate_at(self, now_s: float, stale_after_s: float) -> float:
        """``rate_hz``, or 0 when the last run is more than ``stale_after_s`` before ``now_s``."""
        if not self._times or now_s - self._times[-1] > stale_after_s:
            return 0.0
        return self.rate_hz

    @property
    def rate_hz(self) -> float:
        """Runs per second over the window (0 until two runs were seen)."""
        if len(self._times) < 2:
            return 0.0
        span = self._times[-1] - self._times[0]
        return (len(self._times) - 1) / span if span > 0 else 0.0


class Backoff:
    """Delays between attempts: ``first_s``, then twice as long each failure, up to ``max_s``.

    ``delay_s`` is the wait before the next attempt; ``failed()`` doubles it (and returns the new
    one), ``reset()`` (after a success) starts again from ``first_s``.
    """

    def __init__(self, first_s: float, max_s: float) -> None:
        """Raises ArgumentError: a delay outside ``checks.period``, or ``max_s < first_s``."""
        self.first_s = checks.period(first_s, "first delay")
        self.max_s = checks.period(max_s, "longest delay")
        if self.max_s < self.first_s:
            raise ArgumentError(
                f"longest delay ({self.max_s:g} s) must not be shorter than the first "
                f"({self.first_s:g} s)",
                field="longest delay",
                value=max_s,
            )
        self.delay_s = self.first_s

    def failed(self) -> float:
        """One more failed attempt: the delay doubles (up to ``max_s``); returns it."""
        self.delay_s = min(2 * self.delay_s, self.max_s)
        return self.delay_s

    def reset(self) -> float:
        """A success: the next delay is ``first_s`` again; returns it."""
        self.delay_s = self.first_s
        return self.delay_s


class TickGuard:
    """Keeps a loop alive through a raising tick: the failure is logged once at WARNING (with
    its traceback) until a tick succeeds again, the loop waits a doubling backoff before the
    next tick, and ``health()`` shows it; the first tick that succeeds resumes the rate.

    Args:
        name: the loop's name, in the log.
        first_s: the first wait after a failure (doubling up to ``max_s``).
        max_s: the longest wait between failing ticks.
    """

    def __init__(self, name: str, first_s: float = 0.05, max_s: float = 1.0) -> None:
        self.name = name
        self.backoff = Backoff(first_s, max_s)
        self.failures = 0
        """Ticks that raised since the loop started."""
        self.last_error: str | None = None
        """The last failure's one line while the loop fails; None once a tick succeeded."""
        self._failing = False

    @property
    def failing(self) -> bool:
        """True from a raising tick until one succeeds."""
        return self._failing

    def run(self, tick: Callable[[], None], stopping: threading.Event) -> bool:
        """Run ``tick``; on an exception, ``failed``. True when the tick succeeded."""
        try:
            tick()
        except Exception as exc:
            self.failed(exc, stopping)
            return False
        self.succeeded()
        return True

    def failed(self, exc: Exception, stopping: threading.Event) -> None:
        """A tick raised ``exc``: log it (the first of a run of failures) and wait the backoff
        (or until ``stopping``)."""
        self.failures += 1
        self.last_error = f"{type(exc).__name__}: {exc}"
        if not self._failing:
            self._failing = True
            # a typed error says what went wrong in its line; anything else is a bug: traceback
            logger.warning(
                "%s: a tick failed, retrying with backoff: %s",
                self.name,
                exc,
                exc_info=None if isinstance(exc, PoppyError) else exc,
            )
        stopping.wait(self.backoff.delay_s)
        self.backoff.failed()

    def succeeded(self) -> None:
        """A tick succeeded: after failures, the loop resumes its rate (logged at INFO)."""
        if self._failing:
            self._failing = False
            self.last_error = None
            self.backoff.reset()
            logger.info("%s: recovered after %d failed ticks", self.name, self.failures)

    def health(self) -> dict[str, object]:
        """``ok`` (no failure now), ``failures`` (since the start) and ``last_error``."""
        return {"ok": not self._failing, "failures": self.failures, "last_error": self.last_error}


class Ticker:
    """The one periodic loop body: ``tick(now)`` at each deadline of a drift-free ``Periodic``
    until the tick returns False (its work is done) or ``stopping`` is set.

    A tick that raises goes through a ``TickGuard`` (logged at WARNING once, the loop waits a
    doubling backoff, ``health()`` shows it, the first good tick resumes the rate). A tick that
    overran its period is not followed by a burst: the deadlines it missed are skipped (counted
    in ``missed``), but ``catch_up`` of them (``Periodic``'s).

    Args:
        name: the loop's name, in the log.
        rate_hz: ticks per second (its period goes through ``checks.period``).
        tick: one run; it gets the time it was called at (on ``clock``).
        catch_up: overrun deadlines still run at once (``Periodic``'s ``catch_up``).
        first_s, max_s: the backoff after a failing tick, doubling from one to the other.
        clock: monotonic clock in seconds.
        due: for a tick that paces itself at times (several schedules in one thread, a
            reconnection's backoff): asked before each wait, the time the next tick is due,
            or None for the ticker's own deadline.
        retry: the exceptions retried with backoff; any other one ends the loop (raised to
            the worker: logged once, kept in its ``error``).
        on_failure: called with each retried exception, before the backoff (an owner's own
            health counts it; a follower told to hold).
    """

    def __init__(
        self,
        name: str,
        rate_hz: float,
        tick: Callable[[float], bool | None],
        *,
        catch_up: int = 0,
        first_s: float = 0.05,
        max_s: float = 1.0,
        clock: Callable[[], float] = time.monotonic,
        due: Callable[[], float | None] | None = None,
        retry: tuple[type[Exception], ...] = (Exception,),
        on_failure: Callable[[Exception], None] | None = None,
    ) -> None:
        self.name = name
        self.period_s = checks.period(1.0 / checks.rate(rate_hz))
        self.catch_up = catch_up
        self.guard = TickGuard(name, first_s, max_s)
        self.meter = RateMeter()
        self.schedule: Periodic | None = None
        """The deadlines of the current (or last) run."""
        self._tick = tick
        self._clock = clock
        self._due = due
        self._retry = retry
        self._on_failure = on_failure

    @property
    def missed(self) -> int:
        """Periods skipped because a tick came too late (since the last start)."""
        return 0 if self.schedule is None else self.schedule.missed

    def health(self) -> dict[str, object]:
        """The guard's ``ok``, ``failures``, ``last_error``, and the measured ``rate_hz``."""
        return {**self.guard.health(), "rate_hz": self.meter.rate_hz}

    def run(self, stopping: threading.Event, start_s: float | None = None) -> None:
        """Tick until the tick returns False or ``stopping`` is set; the first deadline is
        ``start_s`` (default: now)."""
        first = self._clock() if start_s is None else start_s
        schedule = self.schedule = Periodic(self.period_s, first, self.catch_up)
        while not stopping.is_set():
            deadline = None if self._due is None else self._due()
            if deadline is None:
                deadline = schedule.next_deadline
            wait = deadline - self._clock()
            if wait > 0 and stopping.wait(wait):
                return
            now = self._clock()
            self.meter.tick(now)
            try:
                outcome = self._tick(now)
            except self._retry as exc:
                if self._on_failure is not None:
                    self._on_failure(exc)
                self.guard.failed(exc, stopping)
                outcome = None
            else:
                self.guard.succeeded()
            if outcome is False:
                return
            schedule.advance(self._clock())
