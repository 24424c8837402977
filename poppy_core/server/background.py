"""Servers started for a robot in background threads (the creature classes' ``use_http`` ...).

Each returns a handle with ``url``, ``run()`` (block until stopped, pypot's call) and ``stop()``.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from poppy_core.server.runner import ServerThread

if TYPE_CHECKING:
    from poppy_core.robot import Robot


class BackgroundServer:
    """A server serving in a thread: ``stop()`` ends it, ``run()`` waits until it ends.

    Args:
        name: what it serves (``"http"``, ``"ws"``...), for messages.
        thread: the uvicorn thread, bound and not yet started.
        on_stop: called once it stopped (to release what it used).
    """

    def __init__(
        self, name: str, thread: ServerThread, on_stop: Callable[[], None] | None = None
    ) -> None:
        self.name = name
        self._thread = thread
        self._on_stop = on_stop
        self._stopped = threading.Event()

    @property
    def host(self) -> str:
        """The address it listens on."""
        return self._thread.host

    @property
    def port(self) -> int:
        """The port it listens on (known once bound)."""
        return self._thread.port

    @property
    def url(self) -> str:
        """``http://host:port``."""
        return self._thread.url

    @property
    def running(self) -> bool:
        """True while it serves."""
        return self._thread.running

    def start(self) -> BackgroundServer:
        """Serve in the background (returns once it serves; again: nothing)."""
        if not self._thread.running and not self._stopped.is_set():
            self._thread.start()
        return self

    def run(self, timeout_s: float | None = None) -> None:
        """Serve and block until ``stop()`` (pypot's ``server.run()``); when it already serves in
        the background (the robot's constructor started it), return at once, as pypot did."""
        if self._thread.running:
            return
        self.start()
        self._stopped.wait(timeout_s)

    def stop(self) -> None:
        """Stop serving (again: nothing)."""
        if not self._stopped.is_set():
            self._stopped.set()
            self._thread.stop()
            if self._on_stop is not None:
                self._on_stop()

    def __repr__(self) -> str:
        return f"<BackgroundServer {self.name} {self.url}>"


def start_http_server(
    robot: Robot, host: str = "127.0.0.1", port: int = 8080, *, start: bool = True, **app: Any
) -> BackgroundServer:
    """Serve the REST API of ``robot`` (``create_app``) on ``host:port`` in a thread.

    Args:
        robot: the robot (the caller keeps and closes it).
        host: the address (loopback by default).
        port: the port; 0 picks a free one.
        start: serve now; False binds only (``start()`` or ``run()`` serves).
        **app: passed to ``create_app`` (``token``, ``policy``...).

    Raises:
        ListenError: the address or port cannot be used (the message says why).
    """
    from poppy_core.server.app import create_app

    server = BackgroundServer("http", ServerThread(create_app(robot, **app), host, port).bind())
    return server.start() if start else server


def start_ws_server(
    robot: Robot,
    host: str = "127.0.0.1",
    port: int = 9009,
    *,
    start: bool = True,
    rate_hz: float = 30.0,
) -> BackgroundServer:
    """Serve the state stream of ``robot`` at ``ws://host:port/`` (pypot's ``use_ws``).

    Raises:
        ListenError: the address or port cannot be used.
    """
    from poppy_core.server.service import RobotService
    from poppy_core.server.stream import create_stream_app

    service = RobotService(robot)
    thread = ServerThread(create_stream_app(service, rate_hz), host, port).bind()
    server = BackgroundServer("ws", thread, on_stop=service.close)
    return server.start() if start else server
