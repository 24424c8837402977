"""Loop machinery: drift-free deadlines, a rate meter, a doubling backoff, a worker thread and
the gate an armed start waits at, and ``close_all`` (every closing step, whatever fails)."""

from __future__ import annotations

import logging
import math
import threading
from collections import deque
from collections.abc import Callable, Iterable

from poppy_core import checks
from poppy_core.errors import ArgumentError

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


class Worker:
    """One background thread running ``body(stopping)`` until it returns or is asked to stop.

    The error story, the same for every loop built on it: an exception that escapes ``body``
    ends the thread, is logged once at WARNING (with its traceback), kept in ``error`` for the
    owner's health, and raised again by ``join``/``stop`` to whoever waits for the thread.
    ``body`` should return soon after ``stopping`` is set (wait on it rather than sleep).

    Args:
        name: the thread's name (also names the worker in the log).
        body: the loop; it receives the event that asks it to stop.
        on_exit: called in the thread after ``body`` ended, whatever the way (cleanup); its
            own exception is logged, never raised.
        quiet: exception types the owner reports itself (say, to the user as a one-line
            error): kept and raised again like any other, but not logged.
    """

    def __init__(
        self,
        name: str,
        body: Callable[[threading.Event], None],
        on_exit: Callable[[], None] | None = None,
        quiet: tuple[type[BaseException], ...] = (),
    ) -> None:
        self.name = name
        self._body = body
        self._on_exit = on_exit
        self._quiet = quiet
        self.stopping = threading.Event()
        self.error: BaseException | None = None
        self._thread: threading.Thread | None = None

    @property
    def running(self) -> bool:
        """True while the thread is alive."""
        return self._thread is not None and self._thread.is_alive()

    def is_current(self) -> bool:
        """True when called from the worker's own thread."""
        return self._thread is not None and self._thread is threading.current_thread()

    def start(self) -> None:
        """Start the thread (no-op while running); a new start forgets the previous error."""
        if self.running:
            return
        self.stopping.clear()
        self.error = None
        self._thread = threading.Thread(target=self._run, name=self.name, daemon=True)
        self._thread.start()

    def request_stop(self) -> None:
        """Ask the body to stop, without waiting."""
        self.stopping.set()

    def join(self, timeout_s: float | None = None) -> bool:
        """Wait for the thread to end; False when it is still running after ``timeout_s``.

        Raises:
            BaseException: the exception that ended the body (kept in ``error``).
        """
        thread = self._thread
        if thread is not None and thread is not threading.current_thread():
            thread.join(timeout_s)
            if thread.is_alive():
                return False
        if self.error is not None:
            raise self.error
        return True

    def wait(self, timeout_s: float | None = None) -> bool:
        """``join`` that does not raise: False while still running after ``timeout_s`` (the
        body's exception, if any, stays in ``error``)."""
        thread = self._thread
        if thread is not None and thread is not threading.current_thread():
            thread.join(timeout_s)
            return not thread.is_alive()
        return True

    def stop(self, timeout_s: float | None = 2.0) -> bool:
        """Ask the body to stop and ``join`` it (from its own thread: only asks)."""
        self.request_stop()
        return self.join(timeout_s)

    def close(self, timeout_s: float | None = 2.0) -> bool:
        """``stop`` for an owner's close: the body's exception is not raised again (it was
        logged and stays in ``error``), so the close goes on freeing what it owns."""
        self.request_stop()
        return self.wait(timeout_s)

    def _run(self) -> None:
        try:
            self._body(self.stopping)
        except BaseException as exc:  # kept for join() and health, logged once
            self.error = exc
            if not isinstance(exc, self._quiet):
                logger.warning("%s failed: %s", self.name, exc, exc_info=exc)
        finally:
            if self._on_exit is not None:
                try:
                    self._on_exit()
                except Exception:
                    logger.exception("%s: cleaning up its thread", self.name)


class Gate:
    """What an armed start waits at: its thread is made ahead and held here until the gate
    opens (go) or is cancelled (a stop came first: the start never happens).

    The owner (a fleet's shared start time) ``open``s it at the start time; whoever stops the
    armed start ``cancel``s it. Only the first of the two counts.

    Attributes:
        at: when the gate is due to open, on the ``time.monotonic()`` clock, or None. A motion
            started through a gate with ``at`` counts its time from ``at``, not from when its
            thread woke (``Primitive.elapsed_time``, ``LoopPrimitive``'s updates, a
            ``MovePlayer``'s frames): robots started by one shared start stay in phase, a late
            thread catching up with what is due. Without it, the time counts from the wake-up.
    """

    def __init__(self, at: float | None = None) -> None:
        self.at = at
        self._event = threading.Event()
        self._lock = threading.Lock()
        self._cancelled = False

    def open(self) -> None:
        """Let the held start go (no-op once cancelled)."""
        with self._lock:
            self._event.set()

    def cancel(self) -> None:
        """Call the start off (no-op once open): its thread ends without starting."""
        with self._lock:
            if not self._event.is_set():
                self._cancelled = True
                self._event.set()

    @property
    def cancelled(self) -> bool:
        """True when the start was called off before the gate opened."""
        return self._cancelled

    def wait(self, timeout_s: float | None = None) -> bool:
        """Block until the gate opens (True) or is cancelled (False); False also on timeout."""
        return self._event.wait(timeout_s) and not self._cancelled


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
        """Run ``tick``; on an exception, log it (the first of a run of failures), wait the
        backoff (or until ``stopping``) and return False. True when the tick succeeded."""
        try:
            tick()
        except Exception as exc:
            self.failures += 1
            self.last_error = f"{type(exc).__name__}: {exc}"
            if not self._failing:
                self._failing = True
                logger.warning(
                    "%s: a tick failed, retrying with backoff: %s", self.name, exc, exc_info=exc
                )
            stopping.wait(self.backoff.delay_s)
            self.backoff.failed()
            return False
        if self._failing:
            self._failing = False
            self.last_error = None
            self.backoff.reset()
            logger.info("%s: recovered after %d failed ticks", self.name, self.failures)
        return True

    def health(self) -> dict[str, object]:
        """``ok`` (no failure now), ``failures`` (since the start) and ``last_error``."""
        return {"ok": not self._failing, "failures": self.failures, "last_error": self.last_error}


def close_all(
    steps: Iterable[tuple[str, Callable[[], object]]], log: logging.Logger, whole: str
) -> None:
    """Run every closing step in order whatever fails first; each failure is logged once at
    WARNING (``"closing {whole}: {step} failed: ..."``) and the next step runs.

    A ``KeyboardInterrupt`` or ``SystemExit`` during a step (Ctrl-C twice) is raised again once
    every step ran, so that nothing is left open by it.
    """
    interrupted: BaseException | None = None
    for what, step in steps:
        try:
            step()
        except Exception as exc:
            log.warning("closing %s: %s failed: %s", whole, what, str(exc) or type(exc).__name__)
        except BaseException as exc:
            interrupted = interrupted or exc
    if interrupted is not None:
        raise interrupted
