"""Server test helpers: a virtual Ergo Jr served over real HTTP on 127.0.0.1."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

from poppy_core import from_profile
from poppy_core.robot import Robot
from poppy_core.server import ServerThread, create_app


@dataclass
class Served:
    """A served robot: its URL, the robot itself and the app."""

    url: str
    robot: Robot
    app: Any


def serve(moves_folder: str, **options: Any) -> Iterator[Served]:
    """Serve a fresh virtual Ergo Jr until the generator is closed."""
    yield from serve_robot(from_profile("ergo-jr", sim=True), **options)


def serve_robot(robot: Robot, **options: Any) -> Iterator[Served]:
    """Serve ``robot`` (``create_app``'s ``options``) until the generator is closed; close it."""
    app = create_app(robot, **options)
    server = ServerThread(app).start()
    try:
        yield Served(server.url, robot, app)
    finally:
        server.stop()
        robot.close()
