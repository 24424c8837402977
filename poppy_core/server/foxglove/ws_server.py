"""``FoxgloveServer``: foxglove-sdk's WebSocket server over a robot (``poppy serve --foxglove``).

Foxglove (the app, desktop or web) connects to ``ws://HOST:PORT`` and subscribes to the
publisher's channels; its 3D panel fetches the URDF's meshes from the server (``package://``
URLs, the ``assets`` capability). The server only shows the robot: it takes no command (no
client publishing, no services, no parameters).

foxglove-sdk's server has no authentication: it cannot ask for the token the other servers
require. The spec a robot is served with (``ServeSpec``, ``assembly/serve_checks.py``)
refuses it on an address other machines reach while a token is required; on loopback it serves
this machine's programs only, as the default does.
"""

from __future__ import annotations

import logging
import re
from typing import TYPE_CHECKING

import foxglove
from foxglove import Context
from foxglove.websocket import ChannelView, Client, ServerListener, WebSocketServer

from poppy_core.server.errors import ListenError
from poppy_core.server.foxglove.publisher import FoxglovePublisher
from poppy_core.server.runner import listen_error

if TYPE_CHECKING:
    from poppy_core.robot import Robot

logger = logging.getLogger(__name__)

DEFAULT_PORT = 8765
"""Foxglove's usual WebSocket port (foxglove_bridge's and the SDK's)."""
_OS_ERROR = re.compile(r"os error (\d+)")
SDK_CLIENT_LOGGER = "foxglove.websocket.connected_client.poller"
"""Where foxglove-sdk logs what happens to one client's connection."""
CLIENT_ERROR = "Error receiving from client"
"""How that logger's lines about a connection the client broke begin."""


class _ClientGone(logging.Filter):
    """foxglove-sdk logs a client that left without closing (a closed tab, a dropped Wi-Fi, a
    reset connection) at ERROR: it is a client's doing, logged at INFO like the other servers'
    lost clients."""

    def filter(self, record: logging.LogRecord) -> bool:
        if record.levelno >= logging.ERROR and record.getMessage().startswith(CLIENT_ERROR):
            record.levelno, record.levelname = logging.INFO, "INFO"
            return logging.getLogger(record.name).isEnabledFor(logging.INFO)
        return True


def _client_resets_at_info() -> None:
    sdk = logging.getLogger(SDK_CLIENT_LOGGER)
    if not any(isinstance(f, _ClientGone) for f in sdk.filters):
        sdk.addFilter(_ClientGone())


class _Listener(ServerListener):
    """A client subscribing to a channel gets the URDF and health at once."""

    def __init__(self, publisher: FoxglovePublisher) -> None:
        self.publisher = publisher

    def on_subscribe(self, client: Client, channel: ChannelView) -> None:
        self.publisher.listening()


class FoxgloveServer:
    """The robot on foxglove-sdk's WebSocket server, bound on ``host:port`` (0: a free port).

    Args:
        robot: the robot shown.
        host: the address to listen on.
        port: the port (0 picks a free one).
        name: the robot's name (the server's name in Foxglove).
        state_rate_hz: joint states and transforms per second.

    Raises:
        ListenError: the port is taken or the address is not this machine's.
    """

    def __init__(
        self,
        robot: Robot,
        host: str,
        port: int,
        name: str,
        *,
        state_rate_hz: float = 50.0,
    ) -> None:
        _client_resets_at_info()
        self.host = host
        self.name = name
        self.context = Context()
        self.publisher = FoxglovePublisher(robot, self.context, name, state_rate_hz=state_rate_hz)
        self.assets = self.publisher.assets
        try:
            self._server: WebSocketServer | None = foxglove.start_server(
                name=f"poppy {name}",
                host=host,
                port=port,
                server_listener=_Listener(self.publisher),
                asset_handler=self.assets.fetch if self.assets is not None else None,
                context=self.context,
            )
        except RuntimeError as exc:  # the SDK's FoxgloveError: "Failed to bind port: ..."
            self.publisher.close()
            raise _bind_error(exc, host, port) from None
        self.port = self._server.port

    @property
    def url(self) -> str:
        """``ws://HOST:PORT`` (what Foxglove's "Open connection" takes)."""
        host = f"[{self.host}]" if ":" in self.host else self.host
        return f"ws://{host}:{self.port}"

    @property
    def running(self) -> bool:
        """True while the server serves and the publisher publishes."""
        return self._server is not None and self.publisher.running

    def start(self) -> None:
        """Publish (the server already listens)."""
        self.publisher.start()

    def stop(self) -> None:
        """Stop publishing, then the server (every client is disconnected)."""
        self.publisher.stop()
        server, self._server = self._server, None
        if server is not None:
            server.stop()
        self.publisher.close()


def _bind_error(exc: RuntimeError, host: str, port: int) -> ListenError:
    match = _OS_ERROR.search(str(exc))
    if match is None:
        return ListenError(f"cannot listen on {host}:{port}: {exc}")
    import os

    code = int(match.group(1))
    return listen_error(OSError(code, os.strerror(code)), host, port)
