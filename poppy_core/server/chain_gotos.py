"""The v1 chain gotos running (``POST /api/v1/chains/{chain}/goto``): each leases its motors.

A chain goto is a strict writer, as a v1 goto is: the service's goal step refuses it when one of
its active motors is driven by another owner. While it runs it holds a lease (``chain arm goto
from 127.0.0.1``) on those motors, so a v1, Zenoh or ROS 2 goal for one of them is refused
(pypot's routes still write). The lease lapses when the goto ends or is cancelled; the
robot-wide stop frees it and stops a straight move's waypoints.
"""

from __future__ import annotations

import contextlib
import threading
from collections.abc import Callable, Hashable

from poppy_core.motion.cartesian import RobotChain
from poppy_core.motion.leases import Lease, MotorLeases
from poppy_core.motion.straight_line import LinearMove
from poppy_core.robot import GotoHandle

ChainMove = GotoHandle | LinearMove
STOP_JOIN_S = 5.0
"""How long the robot-wide stop waits for a straight move's thread to end."""


def chain_holder(chain: RobotChain, client: str) -> Hashable:
    """Who writes through a chain goto's lease: the next goto of the same chain from the same
    client replaces the running one (as a goto replaces a goto); every other writer is refused."""
    return ("chain goto", chain.name, client)


class ChainGotos:
    """The chain gotos started through v1, a lease each (``leases``)."""

    def __init__(self, leases: MotorLeases) -> None:
        self.leases = leases
        self._lock = threading.Lock()
        self._running: list[ChainMove] = []

    def start(self, chain: RobotChain, client: str, begin: Callable[[], ChainMove]) -> ChainMove:
        """Lease the chain's active motors, then ``begin`` the goto; the lease lapses with it.

        Raises:
            MotorLeasedError: a motor another owner drives (nothing moved).
            KinematicsError: what ``begin`` raises (the lease is released).
        """
        holder = chain_holder(chain, client)
        lease = Lease("chain", f"{chain.label} goto", client, holder=holder)
        self.leases.take(lease, [m.name for m in chain.active_motors])
        try:
            handle = begin()
        except BaseException:
            self.leases.release(lease)
            raise
        lease.alive = lambda: not handle.done
        with self._lock:
            self._running = [h for h in self._running if not h.done] + [handle]
        return handle

    def stop_all(self) -> None:
        """Stop the straight moves' waypoints (a goto is cancelled by the goal written after)."""
        with self._lock:
            running, self._running = self._running, []
        for handle in running:
            if isinstance(handle, LinearMove) and not handle.done:
                handle.cancel()
                with contextlib.suppress(Exception):  # its failure was logged by its thread
                    handle.wait(STOP_JOIN_S)
