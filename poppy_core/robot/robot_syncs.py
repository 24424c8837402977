"""The robot's sync loops and ports: started, stopped, run or driven by hand, measured, let go.

``SyncLoops`` is a base of ``Robot`` (``poppy_core.robot.robot``): each call here goes to the
robot's ``BusSync`` (one per bus, ``poppy_core.robot.sync``), whose loops read and write the
motors while the robot lives; ``release_motors`` closes their ports for another program and
``take_motors`` opens them again.
"""

from __future__ import annotations

import logging
from collections.abc import Iterator
from contextlib import contextmanager
from typing import TYPE_CHECKING, Protocol

from poppy_core.errors import RobotClosedError

if TYPE_CHECKING:
    import threading

    from poppy_core.bus import DxlBus
    from poppy_core.robot.goto import GotoRunner
    from poppy_core.robot.health import BusHealth, SyncStats
    from poppy_core.robot.motor import Motor
    from poppy_core.robot.sync import BusSync

logger = logging.getLogger(__name__)


class SyncLoopsHost(Protocol):
    """What ``SyncLoops`` needs of the robot it is mixed into (``Robot`` gives it)."""

    buses: dict[str, DxlBus]
    _syncs: list[BusSync]
    _motors: list[Motor]
    _runner: GotoRunner
    _close_lock: threading.Lock
    _closed: bool

    @property
    def released(self) -> bool:
        """True while the motors are released (``SyncLoops`` gives it)."""
        ...

    @property
    def ports(self) -> list[str]:
        """The ports of the robot's buses (``SyncLoops`` gives it)."""
        ...


class SyncLoops:
    """Start, stop, run and drive the sync loops of a ``SyncLoopsHost`` (a ``Robot``), read their
    stats and health, and let go of its ports and take them back."""

    # -- letting go of the buses ------------------------------------------------------------

    @property
    def released(self: SyncLoopsHost) -> bool:
        """True while the motors are released (``release_motors``): their ports are closed."""
        return any(sync.released for sync in self._syncs)

    def release_motors(self: SyncLoopsHost) -> list[str]:
        """Let go of the motors: gotos cancelled, every motor compliant, the sync loops stopped
        and the ports closed, so that another program can open them (a notebook, `poppy
        scan`). The motors read offline until ``take_motors``. Stop primitives and moves first
        (``RobotService.release_motors`` does). Returns the ports closed.

        Raises:
            RobotClosedError: the robot is closed.
        """
        with self._close_lock:
            if self._closed:
                raise RobotClosedError("the robot is closed: nothing to release")
            for motor in self._motors:
                self._runner.cancel(motor)
                if not self.released:
                    motor.compliant = True
            for sync in self._syncs:
                if not sync.released:
                    sync.release_port()
        logger.warning("motors released: %s closed", ", ".join(self.ports) or "no port")
        return self.ports

    def take_motors(self: SyncLoopsHost) -> list[str]:
        """Take the motors back after ``release_motors``: reopen the ports, ping and read the
        motors, restart the sync loops. They stay compliant. Returns the ports opened.

        Raises:
            PortError: a port cannot be opened (another program still holds it): close that
                program and take them again (the buses opened stay open).
            RobotClosedError: the robot is closed.
        """
        with self._close_lock:
            if self._closed:
                raise RobotClosedError("the robot is closed: open it again")
            for sync in self._syncs:
                if sync.released:
                    sync.take_port()
        logger.warning("motors taken back: %s open", ", ".join(self.ports) or "no port")
        return self.ports

    @property
    def ports(self: SyncLoopsHost) -> list[str]:
        """The ports of the robot's buses, in controller order."""
        return [bus.port for bus in self.buses.values()]

    # -- loops -------------------------------------------------------------------------------

    def start_sync(self: SyncLoopsHost) -> None:
        """Start the sync loops (``from_config`` does it)."""
        for sync in self._syncs:
            sync.start()

    def stop_sync(self: SyncLoopsHost) -> None:
        """Stop the sync loops (pending writes are sent first)."""
        for sync in self._syncs:
            sync.stop()

    def run_loop(self: SyncLoopsHost, name: str) -> None:
        """Run the sync loop ``name`` once now on every bus that has it, from the calling thread.

        ``"present"`` reads the present state, ``"goals"`` sends the goals set since the last
        write. Errors propagate (a silent motor is counted and goes offline as in the thread).
        """
        for sync in self._syncs:
            if sync.has_loop(name):
                sync.run_once(name)

    @contextmanager
    def driving(self: SyncLoopsHost, name: str) -> Iterator[None]:
        """Within the block the sync threads skip loop ``name``: the caller runs it with
        ``run_loop`` at its own pace (teleoperation reads a leader so, right before using it)."""
        for sync in self._syncs:
            sync.drive(name)
        try:
            yield
        finally:
            for sync in self._syncs:
                sync.release(name)

    def sync_stats(self: SyncLoopsHost) -> dict[str, SyncStats]:
        """Controller name -> measured loop rates, error counts and offline motors."""
        return {sync.controller: sync.stats() for sync in self._syncs}

    def health(self: SyncLoopsHost) -> dict[str, BusHealth]:
        """Controller name -> its bus's health: connected, loop rates, errors, offline motors."""
        return {sync.controller: sync.health() for sync in self._syncs}
