"""The sensor contract: a name, registers, a background update at its own rate, health.

A sensor starts on first use (a register read or ``start()``): the first read waits for the
first value, later reads return the latest one at once. ``update()`` runs in the sensor's own
thread at ``rate_hz``. A device that goes away (``SensorLost``) is logged at WARNING once,
shown in ``health()``, reopened with backoff (``reconnect()``) and resumes; one WARNING says
it is back. Other failures of ``update()`` are counted like a motor's failed reads.

A device already away when the sensor is made (a camera unplugged or busy: an accessory) is
the same story from the start (``begin_lost``): the robot starts, one WARNING says so, health
shows it lost, and a background thread reopens it with backoff; once open, that thread stops
until the sensor's first use, so a camera nobody reads still grabs nothing.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, ClassVar

from poppy_core import checks
from poppy_core.errors import ArgumentError, SensorError
from poppy_core.schedule import Backoff, RateMeter, Ticker, Worker

logger = logging.getLogger(__name__)

FIRST_VALUE_TIMEOUT_S = 5.0
"""How long the first read of a sensor waits for its first value."""
BACKOFF_START_S = 0.25
BACKOFF_MAX_S = 5.0


class SensorLost(SensorError):
    """The device behind a sensor stopped answering (unplugged, closed by another program)."""


@dataclass(frozen=True)
class SensorHealth:
    """Is one sensor well? ``Robot.sensor_health()`` gives one per sensor.

    Same shape as the buses' health: ``ok``, ``connected``, ``running``, ``down_s``, ``losses``,
    measured and target rates, error counters, and ``as_dict()`` for ``--json`` and REST.

    Attributes:
        name: the sensor's name (``camera``, ``marker_detector``...).
        kind: its type (``OpenCVCamera``, ``SimCamera``, ``MarkerDetector``...).
        connected: False while its device is lost (it is reopened with backoff).
        running: its background thread is alive (False before first use and after close).
        down_s: seconds since the device was lost (0 while connected).
        losses: times the device was lost.
        rate_hz: updates per second measured now.
        target_hz: updates per second asked for.
        errors: failed updates since the start.
        last_error: the last failure's message ("" when none).
        age_s: seconds since the last good update (None before the first one).
    """

    name: str
    kind: str
    connected: bool
    running: bool
    down_s: float
    losses: int
    rate_hz: float
    target_hz: float
    errors: int
    last_error: str
    age_s: float | None

    @property
    def ok(self) -> bool:
        """Connected (a sensor not started yet is well)."""
        return self.connected

    def as_dict(self) -> dict[str, object]:
        """Plain data (for ``--json`` and the REST API)."""
        data = dict(vars(self))
        data["ok"] = self.ok
        data["rate_hz"] = round(self.rate_hz, 2)
        data["down_s"] = round(self.down_s, 3)
        data["age_s"] = None if self.age_s is None else round(self.age_s, 3)
        return data


class Sensor:
    """Base of every sensor: subclasses give ``registers`` and implement ``update``.

    Args:
        name: the sensor's name (``robot.<name>``).
        rate_hz: how often ``update`` runs once started.
        clock: monotonic clock in seconds.
    """

    registers: ClassVar[tuple[str, ...]] = ()
    """Names readable as attributes and through REST (pypot's ``registers``)."""
    writable: ClassVar[tuple[str, ...]] = ()
    """Registers that may be set through REST."""

    def __init__(
        self, name: str, rate_hz: float, *, clock: Callable[[], float] = time.monotonic
    ) -> None:
        try:
            checks.rate(rate_hz, "its rate")
        except ArgumentError as exc:
            raise SensorError(f"sensor {name!r}: {exc}", sensor=name) from None
        self._name = name
        self._rate_hz = float(rate_hz)
        self._clock = clock
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._first = threading.Event()
        self._thread: Worker | None = None
        self._closed = False
        self._rate = RateMeter(window=30)
        self._connected = True
        self._down_since = 0.0
        self._losses = 0
        self._errors = 0
        self._last_error = ""
        self._backoff = Backoff(BACKOFF_START_S, BACKOFF_MAX_S)
        self._next_retry = 0.0
        self._ticker = Ticker(
            f"sensor {name}",
            self._rate_hz,
            self._loop_tick,
            catch_up=1,
            clock=clock,
            due=self._loop_due,
            on_failure=self._update_failed,
        )
        self._last_good: float | None = None
        self._fatal = ""
        self._bad_inputs = 0
        self._watching = False
        """The thread only reopens a device that was away at start (nobody read the sensor)."""

    # -- what subclasses implement -----------------------------------------------------------

    def update(self) -> bool | None:
        """One background step (grab a frame, detect markers...).

        Returns:
            False when the step brought no value yet (a serial line still on its way): the
            first read goes on waiting; anything else counts as a value.

        Raises:
            SensorLost: the device went away (``reconnect`` is then retried with backoff).
            Exception: any other failure is counted and logged once; the loop goes on with
                backoff (``schedule.Ticker``).
        """
        raise NotImplementedError

    def reconnect(self) -> None:
        """Reopen the device after ``SensorLost`` (raise ``SensorError`` while it is away)."""

    def release(self) -> None:
        """Free the device (called once, by ``close``, after the thread stopped)."""

    def thread_ended(self) -> None:
        """Free what belongs to the sensor's thread (an OpenGL context), in that thread."""

    def fail(self, reason: str) -> None:
        """Give up for good (no OpenGL, no such camera in the model): reads raise at once."""
        self._fatal = reason
        self._last_error = reason
        self._first.set()
        self._stop.set()
        self.wake()

    def bad_input(self, reason: str) -> None:
        """Count one bad input the device sent (a broken line) in health; the loop goes on.

        The first one of a sensor is logged at WARNING, the others only counted.
        """
        if not self._bad_inputs:
            logger.warning("%s %s: %s (further ones only counted)", self.kind, self._name, reason)
        self._bad_inputs += 1
        self._errors += 1
        self._last_error = reason

    def wake(self) -> None:
        """Wake the threads waiting for a value (``Camera`` overrides it)."""

    # -- the contract -----------------------------------------------------------------------

    @property
    def name(self) -> str:
        """The sensor's name."""
        return self._name

    @property
    def kind(self) -> str:
        """Its type name, as a config's ``type`` names it."""
        return type(self).__name__

    @property
    def rate_hz(self) -> float:
        """How often the background update runs."""
        return self._rate_hz

    def clock_s(self) -> float:
        """The sensor's clock now (frame times are on it)."""
        return self._clock()

    @property
    def running(self) -> bool:
        """True while the background thread is alive."""
        thread = self._thread
        return thread is not None and thread.running

    @property
    def closed(self) -> bool:
        """True once ``close`` ran."""
        return self._closed

    def start(self) -> None:
        """Start the background update (idempotent; reading a register does it too). A sensor
        that failed for good (``fail``) stays stopped: its reads raise or stay empty.

        Raises:
            SensorError: the sensor was closed.
        """
        with self._lock:
            if self._closed:
                raise SensorError(f"sensor {self._name!r} is closed", sensor=self._name)
            self._watching = False
            if self._thread is not None or self._fatal:
                return  # running, or failed for good: a read must not revive it (``fail``)
            self._start_thread()

    def _start_thread(self) -> None:
        self._stop.clear()
        # one Worker per run of the thread: a parked thread may still be ending when a read
        # starts the next; the loop waits on the sensor's own stop event (``fail`` sets it too)
        self._thread = Worker(f"sensor {self._name}", self._run, on_exit=self.thread_ended)
        self._thread.start()

    def begin_lost(self, reason: str) -> None:
        """The device is away from the start: warn once, show it lost, reopen it with backoff.

        For accessories (a camera unplugged or busy in another program): the robot starts
        without them and they resume when they can be opened, as after a loss.
        """
        self._lost(reason, at_start=True)
        with self._lock:
            if self._closed or self._thread is not None:
                return
            self._watching = True
            self._start_thread()

    def close(self) -> None:
        """Stop the thread and free the device (idempotent)."""
        with self._lock:
            if self._closed:
                return
            self._closed = True
            thread, self._thread = self._thread, None
        self._stop.set()
        if thread is not None:
            thread.close(2.0)  # a loop that died was logged once and is shown in health
        try:
            self.release()
        except Exception:
            logger.exception("closing sensor %s", self._name)

    def __enter__(self) -> Sensor:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def wait_first(self, timeout_s: float = FIRST_VALUE_TIMEOUT_S) -> None:
        """Start if needed and wait until the first update succeeded.

        Raises:
            SensorError: no value within ``timeout_s`` (with the last failure, if any).
        """
        self.start()
        if self._first.wait(timeout_s) and not self._fatal:
            return
        if self._fatal:
            raise SensorError(f"{self.kind} {self._name!r}: {self._fatal}", sensor=self._name)
        why = f": {self._last_error}" if self._last_error else ""
        raise SensorError(
            f"{self.kind} {self._name!r} gave no value in {timeout_s:g} s{why}", sensor=self._name
        )

    def read(self, register: str) -> Any:
        """The value of ``register`` (what REST's ``value.json`` answers).

        Raises:
            SensorError: not one of this sensor's registers.
        """
        if register not in self.registers:
            known = ", ".join(self.registers)
            raise SensorError(
                f"sensor {self._name!r} has no register {register!r} (registers: {known})",
                sensor=self._name,
            )
        return getattr(self, register)

    def health(self) -> SensorHealth:
        """Connected or not, rate now, errors, age of the latest value."""
        now = self._clock()
        return SensorHealth(
            name=self._name,
            kind=self.kind,
            connected=self._connected and not self._fatal,
            running=self.running,
            down_s=0.0 if self._connected else now - self._down_since,
            losses=self._losses,
            rate_hz=self._rate.rate_at(now, max(1.0, 3.0 / self._rate_hz)),
            target_hz=self._rate_hz,
            errors=self._errors,
            last_error=self._last_error,
            age_s=None if self._last_good is None else now - self._last_good,
        )

    def __repr__(self) -> str:
        return f"<{self.kind} {self._name!r}>"

    # -- the loop ----------------------------------------------------------------------------

    def _run(self, stopping: threading.Event) -> None:
        try:
            self._loop()
        except BaseException as exc:  # the worker logs it once and keeps it; health shows it
            self._errors += 1
            self._last_error = str(exc) or type(exc).__name__
            raise

    def _loop(self) -> None:
        self._ticker.run(self._stop)

    def _loop_due(self) -> float | None:
        """While the device is away: the next reopening; else the ticker's own deadline."""
        return None if self._connected else self._next_retry

    def _loop_tick(self, now: float) -> bool | None:
        if not self._connected:
            self._reopen(now)
            return not (self._connected and self._park())
        try:
            fresh = self.update()
        except SensorLost as exc:
            self._lost(str(exc))
            return None
        if fresh is False:
            return None
        now = self._clock()
        self._rate.tick(now)
        self._last_good = now
        self._first.set()
        return None

    def _update_failed(self, exc: Exception) -> None:
        """An update raised (the ticker logs it once and retries with backoff)."""
        self._errors += 1
        self._last_error = str(exc) or type(exc).__name__

    def _park(self) -> bool:
        """After a device away at start was reopened: end the thread until first use."""
        with self._lock:
            if not self._watching or not self._connected or self._closed:
                return False
            self._watching = False
            self._thread = None
            return True

    def _lost(self, reason: str, at_start: bool = False) -> None:
        self._connected = False
        self._down_since = self._clock()
        self._losses += 1
        self._errors += 1
        self._last_error = reason
        self._next_retry = self._down_since + self._backoff.reset()
        if at_start:
            logger.warning(
                "%s %s is not available: %s; starting without it, retrying",
                self.kind,
                self._name,
                reason,
            )
        else:
            logger.warning("%s %s lost: %s; retrying", self.kind, self._name, reason)

    def _reopen(self, now: float) -> None:
        """One attempt at reopening the device; the next one after a doubling backoff."""
        try:
            self.reconnect()
        except Exception as exc:
            self._last_error = str(exc)
            self._next_retry = now + self._backoff.failed()
            return
        self._connected = True
        down_s = self._clock() - self._down_since
        logger.warning("%s %s is back after %.1f s", self.kind, self._name, down_s)
