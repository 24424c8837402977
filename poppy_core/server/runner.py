"""Run an app with uvicorn: in the foreground (``poppy serve``) or in a thread (tests, bench)."""

from __future__ import annotations

import logging
import threading
import time
from typing import Any

logger = logging.getLogger(__name__)

START_TIMEOUT_S = 10.0
WS_MAX_BYTES = 64 * 1024


def uvicorn_server(app: Any, host: str = "127.0.0.1", port: int = 0) -> Any:
    """A ``uvicorn.Server`` for ``app`` (quiet, no access log; ``port=0`` picks a free one)."""
    import uvicorn

    config = uvicorn.Config(
        app,
        host=host,
        port=port,
        log_level="warning",
        access_log=False,
        lifespan="on",
        ws_max_size=WS_MAX_BYTES,
        timeout_graceful_shutdown=3,
    )
    return uvicorn.Server(config)


def bound_port(server: Any) -> int:
    """The port a started server listens on."""
    for sock in server.servers[0].sockets:
        return int(sock.getsockname()[1])
    raise RuntimeError("the server has no socket")


class ServerThread:
    """An app served by uvicorn in a thread, started by ``start`` and stopped by ``stop``.

    Args:
        app: the ASGI app.
        host: address to bind (loopback by default).
        port: port to bind; 0 picks a free one (read ``port`` after ``start``).
    """

    def __init__(self, app: Any, host: str = "127.0.0.1", port: int = 0) -> None:
        self.host = host
        self.server = uvicorn_server(app, host, port)
        self.port = port
        self._thread = threading.Thread(target=self.server.run, name="uvicorn", daemon=True)

    @property
    def url(self) -> str:
        """``http://host:port``."""
        return f"http://{self.host}:{self.port}"

    def start(self) -> ServerThread:
        """Start serving; returns once the socket listens.

        Raises:
            RuntimeError: the server did not start (e.g. the port is taken).
        """
        self._thread.start()
        deadline = time.monotonic() + START_TIMEOUT_S
        while not self.server.started:
            if not self._thread.is_alive() or time.monotonic() > deadline:
                raise RuntimeError(f"the server on {self.host}:{self.port} did not start")
            time.sleep(0.01)
        self.port = bound_port(self.server)
        return self

    @property
    def running(self) -> bool:
        """True while the server thread runs."""
        return self._thread.is_alive()

    def stop(self) -> None:
        """Stop serving and wait for the thread."""
        self.server.should_exit = True
        self._thread.join(timeout=10.0)

    def __enter__(self) -> ServerThread:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()
