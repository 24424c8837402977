"""The worker thread every loop of ``poppy_core`` runs in, and the gate an armed start waits at."""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable

from poppy_core.schedule.pacing import Ticker

logger = logging.getLogger(__name__)


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
        self.ticker: Ticker | None = None
        """The periodic loop a ``Worker.periodic`` runs (its rate, its failures), else None."""
        self._thread: threading.Thread | None = None
        self._start_lock = threading.Lock()

    @classmethod
    def periodic(
        cls,
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
        start_s: Callable[[], float] | None = None,
        on_exit: Callable[[], None] | None = None,
        quiet: tuple[type[BaseException], ...] = (),
    ) -> Worker:
        """A worker whose body is a ``Ticker``: ``tick(now)`` at ``rate_hz`` until it returns
        False or the worker is asked to stop, a raising tick logged once, retried with backoff.

        ``start_s`` gives each start's first deadline (default: now). The other arguments are
        ``Ticker``'s; the ticker is ``worker.ticker`` (its ``health()``, its ``meter``).

        Raises:
            ArgumentError: a rate or a backoff outside ``checks.period``.
        """
        ticker = Ticker(
            name,
            rate_hz,
            tick,
            catch_up=catch_up,
            first_s=first_s,
            max_s=max_s,
            clock=clock,
            due=due,
            retry=retry,
            on_failure=on_failure,
        )

        def body(stopping: threading.Event) -> None:
            ticker.run(stopping, None if start_s is None else start_s())

        worker = cls(name, body, on_exit=on_exit, quiet=quiet)
        worker.ticker = ticker
        return worker

    @property
    def running(self) -> bool:
        """True while the thread is alive."""
        return self._thread is not None and self._thread.is_alive()

    def is_current(self) -> bool:
        """True when called from the worker's own thread."""
        return self._thread is not None and self._thread is threading.current_thread()

    def start(self) -> None:
        """Start the thread (no-op while running); a new start forgets the previous error.

        Atomic: of two threads starting the worker at once, one starts it, the other finds
        it running.
        """
        with self._start_lock:
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
