"""A robot's REST API over real HTTP on 127.0.0.1, for the sensor tests (the robot stays open)."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

import httpx

from poppy_core.robot import Robot


@contextmanager
def rest(robot: Robot) -> Iterator[httpx.Client]:
    """A client of ``robot``'s pypot REST routes, served until the block ends."""
    from poppy_core.server import ServerThread, create_app

    server = ServerThread(create_app(robot)).start()
    try:
        with httpx.Client(base_url=server.url, timeout=30) as client:
            yield client
    finally:
        server.stop()
