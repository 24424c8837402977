"""A uvicorn server serving in a background thread, with pypot's ``run()`` (the creature
classes' ``robot.http`` and ``robot.ws``; ``poppy_core.assembly.serve`` builds them)."""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import TYPE_CHECKING

from poppy_core.server.runner import ServerThread

if TYPE_CHECKING:
    from poppy_core.server.service import RobotService


class BackgroundServer:
    """A server serving in a thread: ``stop()`` ends it, ``run()`` waits until it ends.

    Args:
        name: what it serves (``"http"``, ``"ws"``...), for messages.
        thread: the uvicorn thread, bound and not yet started.
        on_stop: called once it stopped (to release what it used).
        service: the robot service it serves (shared by the servers of one set).
    """

    def __init__(
        self,
        name: str,
        thread: ServerThread,
        on_stop: Callable[[], None] | None = None,
        *,
        service: RobotService | None = None,
    ) -> None:
        self.name = name
        self.service = service
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
    def ports(self) -> list[int]:
        """Every port it listens on: ``port``, then its aliases (the appliance's 80 and 8080)."""
        return self._thread.ports

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
