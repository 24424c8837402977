"""Helpers of the Snap! tests: a served creature, polling for the robot's state."""

from __future__ import annotations

from collections.abc import Iterator

import httpx

from poppy_core import from_profile
from poppy_core.robot import Robot
from poppy_core.server.snap import SnapServer, start_snap_server
from tests.helpers.waiting import eventually as wait_until
from tests.helpers.waiting import http_timeout

__all__ = ["Served", "near", "served_ergo", "wait_until"]

Served = tuple[Robot, SnapServer, httpx.Client]


def served_ergo() -> Iterator[Served]:
    """A virtual Ergo Jr (with its behaviours and chain) served by the Snap! server on a free
    port, and a client of it (a fixture's body: ``yield from served_ergo()``)."""
    robot = from_profile("ergo-jr", sim=True)
    server = start_snap_server(robot, port=0)
    try:
        with httpx.Client(
            base_url=f"http://127.0.0.1:{server.port}", timeout=http_timeout(20.0)
        ) as http:
            yield robot, server, http
    finally:
        server.stop()
        robot.close()


def near(value: float, target: float, tolerance: float = 2.0) -> bool:
    """``value`` within ``tolerance`` degrees of ``target``."""
    return abs(value - target) <= tolerance
