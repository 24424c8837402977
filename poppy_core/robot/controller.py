"""pypot's controller classes: a loop thread of your own (``MotorsController``), and each bus's
sync loops seen as one (``robot._controllers``).

pypot's controllers were the threads syncing a robot's motors with their hardware; scripts
subclassed ``MotorsController`` (``setup``/``update``/``teardown``) and read
``robot._controllers[i]._updated``, set after each sync. Here ``AbstractController`` runs
``update()`` at ``sync_freq`` Hz in a ``Worker`` thread (an ``update`` that raises is logged once
and retried with backoff: ``schedule.Ticker``); ``BusController`` is the same face over
one bus's ``BusSync`` (which keeps its own thread, started and stopped with the robot).
"""

from __future__ import annotations

import threading
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

from poppy_core import checks
from poppy_core.errors import ControllerError
from poppy_core.schedule import Ticker, Worker

if TYPE_CHECKING:
    from poppy_core.robot.sync import BusSync

__all__ = ["AbstractController", "BusController", "MotorsController", "SensorsController"]

START_TIMEOUT_S = 10.0
"""How long ``start()`` waits for ``setup()`` to end."""


class AbstractController:
    """A thread calling ``update()`` at ``sync_freq`` Hz, between ``setup()`` and ``teardown()``.

    ``start()`` returns once ``setup()`` ended; a setup that raised makes ``start()`` raise
    ``ControllerError`` (a ``RuntimeError``, as pypot's), from the setup's exception. The event
    ``_updated`` is set after each ``update()`` (pypot's name).

    Args:
        io: what the controller talks to (closed by ``close()`` when it has a ``close``), or None.
        sync_freq: updates per second.
    """

    def __init__(self, io: Any, sync_freq: float) -> None:
        self.io = io
        self.sync_freq = checks.rate(sync_freq, "sync_freq")
        self._updated = threading.Event()
        self._set_up = threading.Event()
        self._setup_error: BaseException | None = None
        self._worker = Worker(f"controller {type(self).__name__}", self._run)

    def setup(self) -> None:
        """Called in the thread before the first update."""

    def update(self) -> None:
        """One sync, called at ``sync_freq``."""

    def teardown(self) -> None:
        """Called in the thread after the last update."""

    @property
    def period(self) -> float:
        """Seconds between two updates."""
        return 1.0 / self.sync_freq

    @property
    def running(self) -> bool:
        """True while the thread runs."""
        return self._worker.running

    def start(self) -> None:
        """Start the thread and wait for ``setup()`` to end.

        Raises:
            ControllerError: ``setup()`` raised (or did not end within ``START_TIMEOUT_S``).
        """
        if self.running:
            return
        self._set_up.clear()
        self._setup_error = None
        self._worker.start()
        if not self._set_up.wait(START_TIMEOUT_S):
            self._worker.request_stop()
            raise ControllerError(f"{type(self).__name__}.setup did not end in time")
        error = self._setup_error
        if error is not None:
            self._worker.wait(START_TIMEOUT_S)
            raise ControllerError(
                f"{type(self).__name__}.setup failed: {type(error).__name__}: {error}"
            ) from error

    def stop(self, wait: bool = True) -> None:
        """Ask the thread to stop; with ``wait``, return once it ended (teardown done)."""
        self._worker.request_stop()
        if wait:
            self._worker.wait(START_TIMEOUT_S)

    def close(self) -> None:
        """Stop, then close ``io`` (when it has a ``close``)."""
        self.stop()
        closer = getattr(self.io, "close", None)
        if callable(closer):
            closer()

    def _run(self, stopping: threading.Event) -> None:
        try:
            self.setup()
        except Exception as exc:
            self._setup_error = exc
            return
        finally:
            self._set_up.set()
        try:
            tick = self._controller_tick
            Ticker(self._worker.name, self.sync_freq, tick, catch_up=1).run(stopping)
        finally:
            self.teardown()

    def _controller_tick(self, now: float) -> None:
        self.update()
        self._updated.set()


class MotorsController(AbstractController):
    """A controller of ``motors`` (pypot's ``MotorsController(io, motors, sync_freq=50)``)."""

    def __init__(self, io: Any, motors: Sequence[Any], sync_freq: float = 50.0) -> None:
        super().__init__(io, sync_freq)
        self.motors = list(motors)


class SensorsController(AbstractController):
    """A controller of ``sensors`` (pypot's ``SensorsController(io, sensors, sync_freq=50)``)."""

    def __init__(self, io: Any, sensors: Sequence[Any], sync_freq: float = 50.0) -> None:
        super().__init__(io, sync_freq)
        self.sensors = list(sensors)


class BusController(MotorsController):
    """One bus's sync loops as pypot's controller: ``io`` is the bus, ``motors`` its motors,
    ``_updated`` set after each pass of its loops; ``start``/``stop`` start and stop them
    (``robot.start_sync()``/``stop_sync()`` do it for every bus)."""

    def __init__(self, sync: BusSync) -> None:
        rates = [spec.rate_hz for spec in sync.loop_specs]
        super().__init__(sync.bus, sync.motors, max(rates))
        self._sync = sync
        self._updated = sync.updated

    @property
    def running(self) -> bool:
        """True while the bus's sync thread runs."""
        return self._sync.running

    def start(self) -> None:
        """Start the bus's sync thread (no-op when running)."""
        self._sync.start()

    def stop(self, wait: bool = True) -> None:
        """Stop the bus's sync thread (it sends the writes still pending)."""
        self._sync.stop()

    def close(self) -> None:
        """Stop the sync thread; the robot closes the bus (``robot.close()``)."""
        self.stop()
