"""Serve a VirtualBus on a pseudo-terminal or a TCP socket, from a background thread."""

from __future__ import annotations

import contextlib
import logging
import os
import select
import socket
import threading
import time
import tty
from abc import ABC, abstractmethod
from collections.abc import Callable
from types import TracebackType

from poppy_core.emulator.bus import Reply, VirtualBus
from poppy_core.emulator.linespeed import read_pty_baudrate
from poppy_core.emulator.timing import sleep_until
from poppy_core.errors import PortError

logger = logging.getLogger(__name__)

_CHUNK = 4096
_POLL_S = 0.5


class EmulatorServer(ABC):
    """A running emulator endpoint; ``url`` is what a client opens with pyserial.

    Use :func:`serve_pty` or :func:`serve_tcp` to create one. Stop it with :meth:`stop` or a
    ``with`` block.

    Attributes:
        bus: the virtual bus being served.
        url: the pty slave path (``/dev/pts/N``) or ``socket://host:port``.
    """

    def __init__(self, bus: VirtualBus, url: str) -> None:
        self.bus = bus
        self.url = url
        self._stop = threading.Event()
        self._wake_r, self._wake_w = os.pipe()
        self._thread = threading.Thread(target=self._run, name=f"emulator {url}", daemon=True)

    def __enter__(self) -> EmulatorServer:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.stop()

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.url!r})"

    @property
    def running(self) -> bool:
        """True while the serving thread is alive."""
        return self._thread.is_alive()

    def start(self) -> None:
        """Start the serving thread (the ``serve_*`` functions do it)."""
        self._thread.start()

    def stop(self) -> None:
        """Stop serving, join the thread and close the endpoint (idempotent)."""
        if self._stop.is_set():
            return
        self._stop.set()
        os.write(self._wake_w, b"\0")
        if self._thread.is_alive() and self._thread is not threading.current_thread():
            self._thread.join(timeout=5.0)
        self._close()
        os.close(self._wake_r)
        os.close(self._wake_w)

    def _run(self) -> None:
        try:
            self._serve()
        except Exception:
            logger.exception("emulator server %s crashed", self.url)

    @staticmethod
    def _deliver(replies: list[Reply], write: Callable[[bytes], None]) -> None:
        """Write each reply when it is due (precise sleep), through ``write``."""
        for reply in replies:
            if reply.send_at:
                sleep_until(reply.send_at)
            write(reply.data)

    @abstractmethod
    def _serve(self) -> None:
        """Read instruction bytes and answer until stopped."""

    @abstractmethod
    def _close(self) -> None:
        """Release the endpoint's file descriptors or sockets."""


class PtyServer(EmulatorServer):
    """Serves on a pseudo-terminal; the client opens the slave path at some baud rate.

    The pair shares one line discipline: the baud rate the client sets on the slave is read
    back (``TCGETS2``) for each chunk, and motors only hear packets sent at their rate.
    """

    def __init__(self, bus: VirtualBus) -> None:
        master, slave = os.openpty()
        # Raw mode on both ends: no echo, no line editing, no CR/LF translation.
        tty.setraw(master)
        tty.setraw(slave)
        os.set_blocking(master, False)
        self._master = master
        self._slave = slave  # kept open: the pty survives clients closing and reopening it
        super().__init__(bus, os.ttyname(slave))

    def _write(self, data: bytes) -> None:
        try:
            os.write(self._master, data)
        except BlockingIOError:
            logger.debug("pty %s: client not reading, %d bytes dropped", self.url, len(data))

    def _serve(self) -> None:
        while not self._stop.is_set():
            ready, _, _ = select.select([self._master, self._wake_r], [], [], _POLL_S)
            if self._master not in ready:
                continue
            try:
                data = os.read(self._master, _CHUNK)
            except (BlockingIOError, InterruptedError):
                continue
            except OSError as exc:  # EIO: slave side hung up for good
                logger.debug("pty %s: read failed (%s)", self.url, exc)
                time.sleep(0.01)
                continue
            received_at = time.perf_counter()
            line_bps = read_pty_baudrate(self._slave)
            replies = self.bus.receive(data, line_bps=line_bps, received_at=received_at)
            self._deliver(replies, self._write)

    def _close(self) -> None:
        for fd in (self._master, self._slave):
            with contextlib.suppress(OSError):
                os.close(fd)


class TcpServer(EmulatorServer):
    """Serves on a TCP socket (pyserial ``socket://host:port``), one client at a time.

    A TCP link has no line speed: every packet is taken at the bus's ``baudrate``. A new
    connection replaces the previous one.
    """

    def __init__(self, bus: VirtualBus, host: str, port: int) -> None:
        listener = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        listener.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            listener.bind((host, port))
        except (OSError, OverflowError) as exc:  # OverflowError: a port outside 0-65535
            listener.close()
            address = f"{host}:{port}"
            raise PortError(f"cannot listen on {address}: {exc}", port=address) from exc
        listener.listen(1)
        self._listener = listener
        self._client: socket.socket | None = None
        bound_host, bound_port = listener.getsockname()[:2]
        super().__init__(bus, f"socket://{bound_host}:{bound_port}")

    def _send(self, data: bytes) -> None:
        if self._client is None:
            return
        try:
            self._client.sendall(data)
        except OSError as exc:
            logger.debug("%s: send failed (%s)", self.url, exc)

    def _drop_client(self) -> None:
        if self._client is not None:
            self._client.close()
            self._client = None

    def _serve(self) -> None:
        while not self._stop.is_set():
            watched: list[socket.socket | int] = [self._listener, self._wake_r]
            if self._client is not None:
                watched.append(self._client)
            ready, _, _ = select.select(watched, [], [], _POLL_S)
            if self._listener in ready:
                conn, peer = self._listener.accept()
                conn.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
                self._drop_client()
                self._client = conn
                self.bus.reset_input()
                logger.debug("%s: client %s connected", self.url, peer)
            client = self._client
            if client is None or client not in ready:
                continue
            try:
                data = client.recv(_CHUNK)
            except OSError:
                data = b""
            if not data:
                self._drop_client()
                continue
            replies = self.bus.receive(data, received_at=time.perf_counter())
            self._deliver(replies, self._send)

    def _close(self) -> None:
        self._drop_client()
        self._listener.close()


def serve_pty(bus: VirtualBus) -> EmulatorServer:
    """Serve ``bus`` on a new pseudo-terminal.

    Args:
        bus: the virtual bus.

    Returns:
        The running server; open ``server.url`` (e.g. ``/dev/pts/7``) with pyserial.
    """
    server = PtyServer(bus)
    server.start()
    return server


def serve_tcp(bus: VirtualBus, host: str = "127.0.0.1", port: int = 0) -> EmulatorServer:
    """Serve ``bus`` on a TCP socket.

    Args:
        bus: the virtual bus.
        host: address to listen on.
        port: port to listen on (0: any free port).

    Returns:
        The running server; ``server.url`` is ``socket://host:port``.

    Raises:
        PortError: the address cannot be bound.
    """
    server = TcpServer(bus, host, port)
    server.start()
    return server
