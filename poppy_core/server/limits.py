"""Connection limits uvicorn lacks: a deadline, a size and a count for request headers, and a cap
on open connections.

uvicorn keeps a connection that sends nothing, or its headers one byte at a time, for ever, so a
few thousand such sockets exhaust the process's file descriptors. ``guarded_protocol`` wraps
uvicorn's HTTP protocol class:

- **header deadline**: a connection must complete a request's headers within ``header_timeout_s``
  of opening, and of its previous answer (uvicorn's keep-alive timeout closes idle ones sooner);
  a request being answered (a waiting goto, a WebSocket) is never cut;
- **header size**: a request's headers longer than ``MAX_HEADER_BYTES`` or with more than
  ``MAX_HEADER_LINES`` lines are answered ``431`` and the connection closed as soon as the limit
  is passed (uvicorn's httptools parser keeps every header in memory: 8 connections sending
  64 MiB of headers took the server from 83 to 374 MiB);
- **cap**: beyond ``max_connections`` open connections (HTTP and WebSocket), a new one is
  answered ``503`` with a one-line JSON body and closed, before it costs anything more.
  uvicorn's own ``limit_concurrency`` cannot take its place: it answers ``503`` only once a
  request's headers have arrived (``on_headers_complete``), so sockets that send nothing are all
  accepted and each holds a file descriptor until the header deadline.

A refused request's answer is followed by a **lingering close** (RFC 9112, 9.6): the server
half-closes, reads and drops what the client still sends, and closes once the client is quiet
(``LINGER_QUIET_S``), at its end, or after ``LINGER_MAX_S``. Closing at once with the rest of a
too-large head unread makes the kernel reset the connection: the client reads the answer and then
an error (a browser may show only the reset), or loses the answer not yet sent.

It relies on the attributes uvicorn's protocols share (``connections``, ``cycle``, ``transport``,
``loop``, ``on_response_complete``): pyproject bounds uvicorn to the minor versions tested,
``tests/server/test_uvicorn_contract.py`` checks those attributes and
``tests/server/test_limits.py`` pins the behaviour.
"""

from __future__ import annotations

import asyncio
import logging
from typing import Any

from poppy_core.server.refusals import refusal_body

logger = logging.getLogger(__name__)

HEADER_TIMEOUT_S = 10.0
"""Longest wait for a request's headers (seconds)."""
MAX_CONNECTIONS = 1000
"""Most connections open at once (HTTP keep-alive and WebSocket)."""
MAX_HEADER_BYTES = 64 * 1024
"""Longest request line and headers together (bytes); browsers send a few KiB."""
MAX_HEADER_LINES = 100
"""Most lines in a request's head (the request line and its headers)."""
HEAD_END = b"\r\n\r\n"
LINGER_QUIET_S = 0.5
"""After a refusal, how long the client may send nothing before the connection is closed."""
LINGER_MAX_S = 5.0
"""After a refusal, the longest the connection stays open (a client that never stops sending)."""


def _answer(status: int, reason: str, message: str, tip: str) -> bytes:
    body = refusal_body(message, tip)
    head = (
        f"HTTP/1.1 {status} {reason}\r\ncontent-type: application/json\r\n"
        f"content-length: {len(body)}\r\nconnection: close\r\n\r\n"
    )
    return head.encode() + body


def guarded_protocol(base: Any, header_timeout_s: float, max_connections: int) -> Any:
    """A subclass of uvicorn's HTTP protocol class ``base`` with a header deadline and a cap."""
    busy = _answer(
        503,
        "Service Unavailable",
        f"too many connections: this server accepts {max_connections} at once",
        "close idle connections (or WebSockets) and try again",
    )
    too_large = _answer(
        431,
        "Request Header Fields Too Large",
        f"the request's headers are too large: at most {MAX_HEADER_BYTES // 1024} KiB and "
        f"{MAX_HEADER_LINES} lines",
        "send fewer or shorter headers",
    )
    slow = _answer(
        408,
        "Request Timeout",
        f"the request's headers did not arrive within {header_timeout_s:g} s",
        "send the whole request at once",
    )

    class GuardedProtocol(base):  # type: ignore[misc]
        def __init__(self, *args: Any, **kwargs: Any) -> None:
            super().__init__(*args, **kwargs)
            self._deadline: asyncio.TimerHandle | None = None
            self._deadline_cycle: Any = None
            self._partial = False
            self._refused = False
            self._head_bytes = 0
            self._head_lines = 0
            self._head_tail = b""
            self._lingering: Any = None  # the transport closed once the client is quiet
            self._linger_end = 0.0
            self._linger_timer: asyncio.TimerHandle | None = None

        def connection_made(self, transport: Any) -> None:
            if len(self.connections) >= max_connections:
                self._refused = True
                logger.warning("refused a connection: %d already open", len(self.connections))
                transport.write(busy)
                self._linger(transport)
                return
            super().connection_made(transport)
            self._arm()

        def data_received(self, data: bytes) -> None:
            if self._lingering is not None:
                self._linger_on()  # dropped: the client is still sending what was refused
                return
            if self._deadline is not None and self._head_too_large(data):
                self._disarm()
                logger.info("refused a request whose headers passed the size limits")
                self.transport.write(too_large)
                self._linger(self.transport)
                return
            self._partial = True
            super().data_received(data)
            if self._deadline is not None and (
                self.cycle is not self._deadline_cycle or self.transport.get_protocol() is not self
            ):
                self._disarm()  # headers complete (a new cycle), or upgraded to a WebSocket

        def on_response_complete(self) -> None:
            super().on_response_complete()
            if self.cycle is None or self.cycle.response_complete:
                self._arm()  # waiting for the next request's headers (no pipelined one started)

        def connection_lost(self, exc: Exception | None) -> None:
            self._disarm()
            if self._linger_timer is not None:
                self._linger_timer.cancel()
            if not self._refused:
                super().connection_lost(exc)

        def eof_received(self) -> Any:
            if self._lingering is not None:
                return None  # the client is done: the transport closes
            return super().eof_received()

        def _linger(self, transport: Any) -> None:
            """Half-close after a refusal's answer; close once the client is quiet (a lingering
            close: see the module's docstring)."""
            if transport.can_write_eof():
                transport.write_eof()
            self._lingering = transport
            self._linger_end = self.loop.time() + LINGER_MAX_S
            self._linger_on()

        def _linger_on(self) -> None:
            if self._linger_timer is not None:
                self._linger_timer.cancel()
            left = max(0.0, self._linger_end - self.loop.time())
            self._linger_timer = self.loop.call_later(
                min(LINGER_QUIET_S, left), self._lingering.close
            )

        def _head_too_large(self, data: bytes) -> bool:
            """Count the bytes and lines of ``data`` that belong to the head being received."""
            seen = self._head_tail + data
            end = seen.find(HEAD_END)
            head = data if end < 0 else seen[len(self._head_tail) : end + len(HEAD_END)]
            self._head_tail = seen[-(len(HEAD_END) - 1) :]
            self._head_bytes += len(head)
            self._head_lines += head.count(b"\n")
            return self._head_bytes > MAX_HEADER_BYTES or self._head_lines > MAX_HEADER_LINES + 1

        def _arm(self) -> None:
            self._disarm()
            self._partial = False
            self._head_bytes = self._head_lines = 0
            self._head_tail = b""
            self._deadline_cycle = self.cycle
            self._deadline = self.loop.call_later(header_timeout_s, self._expire)

        def _disarm(self) -> None:
            if self._deadline is not None:
                self._deadline.cancel()
                self._deadline = None

        def _expire(self) -> None:
            self._deadline = None
            transport = self.transport
            waiting = self.cycle is self._deadline_cycle and (
                self.cycle is None or self.cycle.response_complete
            )
            if not waiting or transport.is_closing() or transport.get_protocol() is not self:
                return
            if self._partial:
                transport.write(slow)
                self._linger(transport)
            else:
                transport.close()

    GuardedProtocol.__name__ = f"Guarded{base.__name__}"
    GuardedProtocol.__qualname__ = GuardedProtocol.__name__
    return GuardedProtocol


def quiet_denials(base: Any) -> Any:
    """A subclass of uvicorn's WebSocket protocol class ``base`` where a handshake refused with an
    HTTP answer (the guard's 400/401/403, ASGI's denial response) ends the handshake.

    uvicorn's protocol counts only an accept or a close as one, and logs "ASGI callable returned
    without completing handshake" at ERROR for every refused handshake: a page trying the port
    would fill the terminal with false errors.
    """

    class QuietDenials(base):  # type: ignore[misc]
        async def send(self, message: Any) -> None:
            await super().send(message)
            if message["type"] == "websocket.http.response.body" and not message.get(
                "more_body", False
            ):
                self.handshake_complete = True  # answered: nothing is left to complete

    QuietDenials.__name__ = f"QuietDenials{base.__name__}"
    QuietDenials.__qualname__ = QuietDenials.__name__
    return QuietDenials
