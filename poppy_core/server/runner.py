"""Run an app with uvicorn: in the foreground (``poppy serve``) or in a thread (tests, bench).

Sockets are bound here, before uvicorn starts, so that a busy port, a name that does not resolve
or a refused permission is a ``ListenError`` naming the cause (uvicorn only logs it and exits).
"""

from __future__ import annotations

import errno
import logging
import socket
import threading
import time
from typing import Any

from poppy_core.schedule import Worker
from poppy_core.server.errors import ListenError
from poppy_core.server.limits import (
    HEADER_TIMEOUT_S,
    MAX_CONNECTIONS,
    guarded_protocol,
    quiet_denials,
)

logger = logging.getLogger(__name__)

START_TIMEOUT_S = 10.0
WS_MAX_BYTES = 64 * 1024
BACKLOG = 2048
PRIVILEGED_PORTS = 1024


def uvicorn_server(
    app: Any,
    host: str = "127.0.0.1",
    port: int = 0,
    *,
    header_timeout_s: float = HEADER_TIMEOUT_S,
    max_connections: int = MAX_CONNECTIONS,
) -> Any:
    """A ``uvicorn.Server`` for ``app`` (quiet, no access log; ``port=0`` picks a free one).

    Args:
        app: the ASGI app.
        host: address to listen on.
        port: port to listen on.
        header_timeout_s: a connection sending no complete request headers for this long is
            closed (408 when it sent part of them).
        max_connections: beyond this many open connections, new ones get a 503 and are closed.
    """
    import uvicorn
    from uvicorn.protocols.http.auto import AutoHTTPProtocol
    from uvicorn.protocols.websockets.auto import AutoWebSocketsProtocol

    config = uvicorn.Config(
        app,
        host=host,
        port=port,
        http=guarded_protocol(AutoHTTPProtocol, header_timeout_s, max_connections),
        ws=quiet_denials(AutoWebSocketsProtocol) if AutoWebSocketsProtocol else "auto",
        log_level="warning",
        access_log=False,
        lifespan="on",
        ws_max_size=WS_MAX_BYTES,
        backlog=BACKLOG,
        timeout_graceful_shutdown=3,
    )
    return uvicorn.Server(config)


def listen_error(exc: OSError, host: str, port: int) -> ListenError:
    """The cause of a failed bind, in words, with what to do."""
    where = f"{host}:{port}"
    if isinstance(exc, socket.gaierror):
        return ListenError(
            f"cannot listen on {host!r}: the name does not resolve ({exc.strerror}); give an "
            "address of this machine, 127.0.0.1, or 0.0.0.0 for every interface"
        )
    if exc.errno == errno.EADDRINUSE:
        return ListenError(
            f"cannot listen on {where}: the port is already in use (another poppy serve?); "
            "stop that program or choose another port"
        )
    if exc.errno in (errno.EACCES, errno.EPERM):
        low = f": ports below {PRIVILEGED_PORTS} need root" if 0 < port < PRIVILEGED_PORTS else ""
        return ListenError(
            f"cannot listen on {where}: permission denied{low}; choose another port (e.g. 8080)"
        )
    if exc.errno == errno.EADDRNOTAVAIL:
        return ListenError(
            f"cannot listen on {where}: {host} is not an address of this machine; give one of "
            "its addresses, 127.0.0.1, or 0.0.0.0 for every interface"
        )
    return ListenError(f"cannot listen on {where}: {exc.strerror or exc}")


def bind_sockets(host: str, port: int) -> list[socket.socket]:
    """Listening sockets for every address ``host`` resolves to, all on one port.

    Raises:
        ListenError: the name does not resolve, the port is taken, permission denied...
    """
    try:
        infos = socket.getaddrinfo(
            host or None, port, type=socket.SOCK_STREAM, flags=socket.AI_PASSIVE
        )
    except (socket.gaierror, UnicodeError) as exc:
        raise listen_error(
            exc if isinstance(exc, OSError) else socket.gaierror(str(exc)), host, port
        ) from None
    sockets: list[socket.socket] = []
    seen: set[tuple[int, Any]] = set()
    try:
        for family, kind, proto, _, address in infos:
            if (family, address[0]) in seen:
                continue
            seen.add((family, address[0]))
            sock = socket.socket(family, kind, proto)
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            if family == socket.AF_INET6:
                sock.setsockopt(socket.IPPROTO_IPV6, socket.IPV6_V6ONLY, 1)
            if sockets:  # the other addresses of a name share the first one's port
                address = (address[0], sockets[0].getsockname()[1], *address[2:])
            try:
                sock.bind(address)
            except OSError as exc:
                sock.close()
                if sockets and exc.errno in (errno.EADDRNOTAVAIL, errno.EAFNOSUPPORT):
                    logger.debug("not listening on %s: %s", address[0], exc)
                    continue
                raise listen_error(exc, host, port) from None
            sock.listen(BACKLOG)
            sockets.append(sock)
    except BaseException:
        for sock in sockets:
            sock.close()
        raise
    return sockets


class ServerThread:
    """An app served by uvicorn in a thread: ``bind`` (optional), ``start``, ``stop``.

    Args:
        app: the ASGI app.
        host: address to bind (loopback by default).
        port: port to bind; 0 picks a free one (read ``port`` after ``bind`` or ``start``).
        header_timeout_s: see ``uvicorn_server``.
        max_connections: see ``uvicorn_server``.
        alias_ports: more ports on ``host`` serving the same app (the appliance's 8080 beside
            its 80); 0 picks a free one. Read them in ``ports`` after ``bind``.
        sockets: sockets already bound and listening (``bind_sockets``), served instead of
            binding ``port``: a caller that must know the port is free before it builds the app.
    """

    def __init__(
        self,
        app: Any,
        host: str = "127.0.0.1",
        port: int = 0,
        *,
        header_timeout_s: float = HEADER_TIMEOUT_S,
        max_connections: int = MAX_CONNECTIONS,
        alias_ports: tuple[int, ...] = (),
        sockets: list[socket.socket] | None = None,
    ) -> None:
        self.host = host
        self.alias_ports = alias_ports
        self.server = uvicorn_server(
            app, host, port, header_timeout_s=header_timeout_s, max_connections=max_connections
        )
        self._sockets: list[socket.socket] | None = sockets
        self.port = int(sockets[0].getsockname()[1]) if sockets else port
        self._worker = Worker("uvicorn", self._run)

    @property
    def url(self) -> str:
        """``http://host:port``."""
        host = f"[{self.host}]" if ":" in self.host else self.host
        return f"http://{host}:{self.port}"

    def bind(self) -> ServerThread:
        """Bind the listening sockets (``port`` is then known); ``start`` serves them.

        Raises:
            ListenError: the address or port cannot be used (the message says why).
        """
        if self._sockets is None:
            sockets = bind_sockets(self.host, self.port)
            try:
                ports = [int(sockets[0].getsockname()[1])]
                for alias in self.alias_ports:
                    more = bind_sockets(self.host, alias)
                    sockets += more
                    ports.append(int(more[0].getsockname()[1]))
            except BaseException:
                for sock in sockets:
                    sock.close()
                raise
            self._sockets = sockets
            self.port = ports[0]
            self.alias_ports = tuple(ports[1:])
        return self

    @property
    def ports(self) -> list[int]:
        """Every port it listens on: ``port``, then the alias ports (known once bound)."""
        return [self.port, *self.alias_ports]

    def _run(self, stopping: threading.Event) -> None:
        """uvicorn's loop; it ends on ``server.should_exit``, which ``stop`` sets."""
        self.server.run(sockets=self._sockets)

    def start(self) -> ServerThread:
        """Start serving (binding first if ``bind`` was not called); returns once it serves.

        Raises:
            ListenError: the address or port cannot be used.
            RuntimeError: the server did not start (its log says why).
        """
        self.bind()
        self._worker.start()
        deadline = time.monotonic() + START_TIMEOUT_S
        while not self.server.started:
            if not self._worker.running or time.monotonic() > deadline:
                self.close_sockets()
                raise RuntimeError(f"the server on {self.host}:{self.port} did not start")
            time.sleep(0.01)
        return self

    @property
    def running(self) -> bool:
        """True while the server thread runs."""
        return self._worker.running

    def stop(self) -> None:
        """Stop serving and wait for the thread (also releases sockets bound but never served)."""
        self.server.should_exit = True
        self._worker.close(10.0)  # an error that ended uvicorn was logged once
        self.close_sockets()

    def close_sockets(self) -> None:
        """Close the listening sockets."""
        for sock in self._sockets or []:
            sock.close()

    def __enter__(self) -> ServerThread:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()
