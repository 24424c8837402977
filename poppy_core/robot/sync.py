"""Sync loops: one thread per bus reads and writes register groups, each at its own rate.

Defaults follow pypot's controllers. ``base`` (BaseDxlController): present position, speed and
load read at 50 Hz; goal position, moving speed, torque limit, torque enable and LED written at
50 Hz; PID gains or compliance margins/slopes written at 10 Hz; angle limits at 1 Hz; temperature
and voltage read at 1 Hz. ``light`` (LightDxlController) reads only position and speed at 50 Hz
and load, temperature and voltage at 1 Hz. Writes only send values that changed.

Reads use ``DxlBus.sync_read`` (sync read, USB2AX sync read, bulk read or single reads, as the
bus offers), one transaction per group of motors sharing a register layout. A motor that misses
``offline_after`` reads in a row is marked offline: it leaves the fast loops and is pinged (one
offline motor per ``retry_period_s``, in turn) until it answers again. Deadlines are drift-free
(``Periodic``); a run that overran its period is followed at once by the next one, so a loop
whose runs are sometimes long keeps its rate. Reads are stored into, writes taken from and
misses counted on each motor's ``MotorLink`` (``link_of(motor)``), the robot side of a ``Motor``;
a run's transactions are ``SyncTransfers``' (``robot.sync_transfers``).

A lost port (adapter unplugged, emulator gone: a ``PortError``) is logged once at WARNING, every
motor of the bus goes offline at once, and the thread reopens the port with backoff
(``RECONNECT_FIRST_S`` doubling up to ``RECONNECT_MAX_S``); once it opens, the motors are pinged
and resume (one WARNING says the bus is back). ``health()`` says how the bus is doing.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable, Sequence

from poppy_core.bus import DxlBus
from poppy_core.errors import PoppyError, PortError
from poppy_core.robot.health import BusHealth, LoopStats, SyncStats, bus_label
from poppy_core.robot.loops import BASE_LOOPS, LIGHT_LOOPS, LoopSpec, loops_for
from poppy_core.robot.motor import Motor
from poppy_core.robot.motor_link import link_of
from poppy_core.robot.sync_transfers import RETRY, SyncTransfers
from poppy_core.schedule import Backoff, Periodic, RateMeter, Worker

logger = logging.getLogger(__name__)


# Reopening a lost port: first attempt after RECONNECT_FIRST_S, then twice as long each time.
RECONNECT_FIRST_S = 0.1
RECONNECT_MAX_S = 1.0
# A loop that has not run for this many periods (at least STALE_MIN_S) reports a rate of 0.
STALE_PERIODS = 3.0
STALE_MIN_S = 0.5

__all__ = [
    "BASE_LOOPS",
    "LIGHT_LOOPS",
    "BusHealth",
    "BusSync",
    "LoopSpec",
    "LoopStats",
    "SyncStats",
    "loops_for",
]


class _Loop:
    def __init__(self, spec: LoopSpec, start_s: float) -> None:
        self.spec = spec
        self.schedule = Periodic(1.0 / spec.rate_hz, start_s, catch_up=1)
        self.meter = RateMeter()
        self.errors = 0
        self.last_duration_s = 0.0


class BusSync:
    """The sync loops of one bus (one thread).

    Args:
        controller: the controller's name (for logs and stats).
        bus: the open bus.
        motors: the motors on it.
        loops: the register groups (``BASE_LOOPS``, ``LIGHT_LOOPS`` or your own).
        offline_after: consecutive missed reads before a motor is marked offline.
        retry_period_s: time between two pings of offline motors (one motor per ping, in
            turn; see ``sync_transfers.RETRY_BATCH``).
        clock: monotonic clock in seconds.
    """

    def __init__(
        self,
        controller: str,
        bus: DxlBus,
        motors: Sequence[Motor],
        loops: Sequence[LoopSpec] = BASE_LOOPS,
        *,
        offline_after: int = 3,
        retry_period_s: float = 0.2,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.controller = controller
        self.bus = bus
        self.motors = list(motors)
        self._clock = clock
        self._specs = [*loops, LoopSpec(RETRY, (), False, 1.0 / retry_period_s)]
        self._loops: list[_Loop] = []
        self._worker = Worker.periodic(
            f"sync {controller}",
            max(spec.rate_hz for spec in self._specs),
            self._tick,
            catch_up=1,
            clock=clock,
            due=self._due,
        )
        self._stop = self._worker.stopping
        self._start_lock = threading.Lock()
        self._transfers = SyncTransfers(bus, self.motors, offline_after, self._stop)
        self._driven: set[str] = set()
        self.updated = threading.Event()
        """Set after each pass that ran a loop (pypot's ``controller._updated``: clear it, wait
        for it, and the values are one sync newer)."""
        self.connected = bus.is_open
        """False while the port is lost, not there yet (a bus made ``DxlBus.absent``: the
        thread opens it with backoff) or released."""
        self.released = False
        """True between ``release_port`` and ``take_port``: the port is closed on purpose."""
        self.losses = 0
        self._down_since = 0.0 if self.connected else clock()
        self._backoff = Backoff(RECONNECT_FIRST_S, RECONNECT_MAX_S)
        self._next_reopen = 0.0
        if not self.connected:
            for motor in self.motors:
                link_of(motor).mark_offline()

    @property
    def loop_specs(self) -> list[LoopSpec]:
        """The register groups this bus syncs (its retry loop last)."""
        return list(self._specs)

    @property
    def offline_after(self) -> int:
        """Consecutive missed reads before a motor is marked offline."""
        return self._transfers.offline_after

    @property
    def running(self) -> bool:
        """True while the loop thread is alive."""
        return self._worker.running

    def start(self) -> None:
        """Start the thread (no-op when running; of two starts at once, one starts it)."""
        with self._start_lock:
            if self.running:
                return
            now = self._clock()
            self._loops = [_Loop(spec, now) for spec in self._specs]
            self._worker.start()

    def stop(self, timeout_s: float = 2.0) -> None:
        """Stop and join the thread, then send the writes still pending (idempotent)."""
        try:
            if not self._worker.stop(timeout_s):
                logger.warning("sync loop of %s did not stop in %.1f s", self.controller, timeout_s)
        finally:
            self.flush()

    def flush(self) -> None:
        """Send every pending write now, from the calling thread.

        Sync writes get no reply: when something was sent, one ping follows, so the writes
        have been handled once this returns (the bus may be closed right after).
        """
        if not self.connected or not any(
            m.online and link_of(m).has_pending() for m in self.motors
        ):
            return
        for spec in self._specs:
            if spec.write:
                try:
                    self._transfers.write(spec)
                except PoppyError as exc:
                    logger.warning("%s: final writes failed: %s", self.controller, exc)
        online = [m for m in self.motors if m.online]
        if online:
            try:
                self.bus.ping(online[0].id, retries=0)
            except PoppyError as exc:
                logger.debug("%s: no reply after the final writes: %s", self.controller, exc)

    def release_port(self) -> None:
        """Let go of the bus: stop the thread (the writes pending, such as compliance, are sent
        first), drop what is left, mark every motor offline and close the port, so another
        program can open it. ``take_port`` takes it back."""
        self.stop()
        for motor in self.motors:
            link = link_of(motor)
            link.mark_offline()
            link.drop_pending()
        self.connected = False
        self.released = True
        self._down_since = self._clock()
        self.bus.close()

    def take_port(self) -> None:
        """Take the bus back after ``release_port``: reopen the port, ping every motor, read
        their state again, restart the thread.

        Raises:
            PortError: the port cannot be opened (another program holds it, it is gone); the
                bus stays released.
        """
        self.bus.reopen()
        self.released = False
        self.connected = True
        self._stop.clear()  # stopped by release_port: the pings below must run
        try:
            self._transfers.retry(every=True)
        except PortError:
            self.connected = False
            self.released = True
            self.bus.close()
            raise
        self.start()

    def run_once(self, name: str) -> None:
        """Run one loop now (tests and tools); errors propagate."""
        spec = next(s for s in self._specs if s.name == name)
        self._transfers.run(spec)

    def has_loop(self, name: str) -> bool:
        """True when this bus has a loop called ``name``."""
        return any(spec.name == name for spec in self._specs)

    def drive(self, name: str) -> None:
        """Take loop ``name`` away from the thread: it is skipped until ``release``.

        The caller runs it with ``run_once`` at its own pace (teleoperation reads the leader's
        present state at its rate, right before using it).
        """
        self._driven.add(name)

    def release(self, name: str) -> None:
        """Give loop ``name`` back to the thread."""
        self._driven.discard(name)

    def health(self) -> BusHealth:
        """Connected or not, loop rates now, error counters, offline motors."""
        now = self._clock()
        loops = [loop for loop in self._loops if loop.spec.name != RETRY]
        stats = self.bus.stats
        return BusHealth(
            controller=self.controller,
            port=self.bus.port,
            connected=self.connected,
            running=self.running,
            down_s=0.0 if self.connected else now - self._down_since,
            losses=self.losses,
            loop_hz={
                loop.spec.name: loop.meter.rate_at(
                    now, max(STALE_MIN_S, STALE_PERIODS / loop.spec.rate_hz)
                )
                for loop in loops
            },
            target_hz={loop.spec.name: loop.spec.rate_hz for loop in loops},
            loop_errors=sum(loop.errors for loop in self._loops) + self._thread_failures(),
            timeouts=stats.timeouts,
            retries=stats.retries,
            corrupt_packets=stats.corrupt_packets,
            motor_errors=stats.motor_errors,
            offline=[m.name for m in self.motors if not m.online],
        )

    def stats(self) -> SyncStats:
        """Measured rates, error counts and offline motors."""
        loops = {
            loop.spec.name: LoopStats(
                loop.spec.name,
                loop.spec.rate_hz,
                loop.meter.rate_hz,
                loop.meter.count,
                loop.schedule.missed,
                loop.errors,
                loop.last_duration_s,
            )
            for loop in self._loops
        }
        return SyncStats(
            self.controller,
            self.bus.port,
            self.running,
            loops,
            {m.name: m.errors for m in self.motors},
            [m.name for m in self.motors if not m.online],
            self.bus.stats.as_dict(),
        )

    # -- the thread ------------------------------------------------------------------------------

    def _thread_failures(self) -> int:
        ticker = self._worker.ticker
        return ticker.guard.failures if ticker is not None else 0

    def _due(self) -> float:
        """When the thread's next pass is due: the earliest loop, or the next reopening."""
        if self.released:
            return self._clock() + RECONNECT_MAX_S
        if not self.connected:
            return self._next_reopen
        return min(loop.schedule.next_deadline for loop in self._loops)

    def _tick(self, now: float) -> None:
        """One pass of the thread (a failure is the worker's: logged once, backoff, health)."""
        if self.released:
            return
        if self.connected:
            self._run_due_loops(now)
        else:
            self._reconnect()

    def _run_due_loops(self, now: float) -> None:
        ran = False
        for loop in self._loops:
            if self._stop.is_set():
                return
            if not loop.schedule.due(now):
                continue
            if loop.spec.name in self._driven:
                loop.schedule.advance(now)
                continue
            loop.meter.tick(now)
            ran = ran or loop.spec.name != RETRY
            started = self._clock()
            try:
                self._transfers.run(loop.spec)
            except PortError as exc:
                loop.errors += 1
                self._lost(exc)
                return
            except Exception as exc:  # one register group failed; the others go on
                loop.errors += 1
                if isinstance(exc, PoppyError | OSError):
                    logger.debug("%s %s loop: %s", self.controller, loop.spec.name, exc)
                else:
                    logger.exception("%s %s loop failed", self.controller, loop.spec.name)
            loop.last_duration_s = self._clock() - started
            loop.schedule.advance(now)
        if ran:
            self.updated.set()

    def _lost(self, exc: PortError) -> None:
        """The port went away: every motor offline now, one warning, reopen with backoff."""
        self.connected = False
        self.losses += 1
        self._down_since = self._clock()
        self._next_reopen = self._down_since + self._backoff.reset()
        for motor in self.motors:
            link_of(motor).mark_offline()
        count = len(self.motors)
        logger.warning(
            "bus %s: lost %s (%s); its %d %s offline, reopening it with backoff",
            bus_label(self.controller, self.bus.port),
            self.bus.port,
            exc,
            count,
            "motor is" if count == 1 else "motors are",
        )

    def _reconnect(self) -> None:
        try:
            self.bus.reopen()
        except PortError as exc:
            self._next_reopen = self._clock() + self._backoff.failed()
            logger.debug("%s: %s still away (%s)", self.controller, self.bus.port, exc)
            return
        now = self._clock()
        self.connected = True
        logger.warning(
            "bus %s: %s is back after %.1f s; pinging its motors",
            bus_label(self.controller, self.bus.port),
            self.bus.port,
            now - self._down_since,
        )
        for loop in self._loops:
            loop.schedule = Periodic(loop.schedule.period_s, now, catch_up=1)
        try:
            self._transfers.retry(every=True)
        except PortError as exc:
            self._lost(exc)
