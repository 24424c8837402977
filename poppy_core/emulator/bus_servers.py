"""Serve a VirtualBus on a pseudo-terminal or a TCP socket (see ``serving`` for the threads)."""

from __future__ import annotations

import contextlib
import logging
import os
import socket
import time
import tty
from pathlib import Path
from typing import Protocol

from poppy_core.emulator.bus import VirtualBus
from poppy_core.emulator.linespeed import read_pty_baudrate
from poppy_core.emulator.link import LinkServer
from poppy_core.emulator.serving import CHUNK, RESET, EmulatorServer
from poppy_core.errors import PortError

__all__ = [
    "EmulatorServer",
    "Endpoint",
    "LinkServer",
    "PtyServer",
    "TcpServer",
    "serve_pty",
    "serve_tcp",
]

logger = logging.getLogger(__name__)


class Endpoint(Protocol):
    """What serves a ``VirtualBus``: a pty/TCP ``EmulatorServer`` or an in-process link."""

    bus: VirtualBus
    url: str
    replies_dropped: int

    @property
    def running(self) -> bool:
        """True while serving."""
        ...

    @property
    def connected(self) -> bool:
        """False while the line is down."""
        ...

    def stop(self) -> None:
        """Stop serving (idempotent)."""
        ...

    def lose(self, duration_s: float) -> None:
        """Take the line away for ``duration_s`` seconds."""
        ...


class PtyServer(EmulatorServer):
    """Serves on a pseudo-terminal; the client opens the slave path at some baud rate.

    The pair shares one line discipline: the baud rate the client set on the slave is read
    back (``TCGETS2``) for each chunk, and motors only hear packets sent at their rate.

    Args:
        bus: the virtual bus.
        link: a symlink made to point at the slave (replaced atomically, removed on stop), so
            clients have a path that survives :meth:`lose`, as ``/dev/serial/by-id`` does.
    """

    def __init__(self, bus: VirtualBus, link: str | os.PathLike[str] | None = None) -> None:
        self._master: int | None = None
        self._slave: int | None = None
        self.link = Path(link) if link is not None else None
        url = self._open_pty()
        super().__init__(bus, url)

    def _open_pty(self) -> str:
        master, slave = os.openpty()
        # Raw mode on both ends: no echo, no line editing, no CR/LF translation.
        tty.setraw(master)
        tty.setraw(slave)
        os.set_blocking(master, False)
        self._master = master
        self._slave = slave  # kept open: the pty survives clients closing and reopening it
        path = os.ttyname(slave)
        if self.link is not None:
            temporary = self.link.with_name(f".{self.link.name}.{os.getpid()}.tmp")
            with contextlib.suppress(FileNotFoundError):
                temporary.unlink()
            try:
                os.symlink(path, temporary)
                os.replace(temporary, self.link)
            except OSError as exc:
                os.close(master)
                os.close(slave)
                raise PortError(
                    f"cannot link {self.link} to {path}: {exc}", port=str(self.link)
                ) from exc
        return path

    def _watched(self) -> list[int | socket.socket]:
        return [] if self._master is None else [self._master]

    def _on_readable(self, ready: list[int | socket.socket]) -> None:
        master, slave = self._master, self._slave
        if master is None or master not in ready:
            return
        try:
            data = os.read(master, CHUNK)
        except (BlockingIOError, InterruptedError):
            return
        except OSError as exc:  # EIO: no slave open (cannot happen while we hold one)
            logger.debug("pty %s: read failed (%s)", self.url, exc)
            time.sleep(0.01)
            return
        line_bps = read_pty_baudrate(slave) if slave is not None else None
        self._put(data, line_bps)

    def _write_some(self, view: memoryview) -> int | None:
        if self._master is None:
            return None
        try:
            return os.write(self._master, view)
        except BlockingIOError:
            return 0

    def _writable_fd(self) -> int | None:
        return self._master

    def _open_endpoint(self) -> bool:
        self.url = self._open_pty()
        return True

    def _close_endpoint(self) -> None:
        if self.link is not None and self._slave is not None:
            with contextlib.suppress(OSError):
                if os.readlink(self.link) == self.url:
                    self.link.unlink()
        for fd in (self._master, self._slave):
            if fd is not None:
                with contextlib.suppress(OSError):
                    os.close(fd)
        self._master = self._slave = None


class TcpServer(EmulatorServer):
    """Serves on a TCP socket (pyserial ``socket://host:port``), one client at a time.

    A TCP link has no line speed: every packet is taken at the bus's ``baudrate``. A new
    connection replaces the previous one.
    """

    def __init__(self, bus: VirtualBus, host: str, port: int) -> None:
        self._client: socket.socket | None = None
        self._listener: socket.socket | None = None
        self._address = (host, port)
        try:
            self._listener = self._listen(host, port)
        except (OSError, OverflowError) as exc:  # OverflowError: a port outside 0-65535
            address = f"{host}:{port}"
            raise PortError(f"cannot listen on {address}: {exc}", port=address) from exc
        bound_host, bound_port = self._listener.getsockname()[:2]
        self._address = (bound_host, bound_port)
        super().__init__(bus, f"socket://{bound_host}:{bound_port}")

    @staticmethod
    def _listen(host: str, port: int) -> socket.socket:
        listener = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        listener.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            listener.bind((host, port))
            listener.listen(1)
        except BaseException:
            listener.close()
            raise
        return listener

    def _watched(self) -> list[int | socket.socket]:
        watched: list[int | socket.socket] = []
        if self._listener is not None:
            watched.append(self._listener)
        if self._client is not None:
            watched.append(self._client)
        return watched

    def _on_readable(self, ready: list[int | socket.socket]) -> None:
        listener = self._listener
        if listener is not None and listener in ready:
            try:
                conn, peer = listener.accept()
            except OSError:
                return
            conn.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            conn.setblocking(False)
            with self._io_lock:
                self._drop_client()
                self._client = conn
            self._inbox.put(RESET)
            logger.debug("%s: client %s connected", self.url, peer)
        client = self._client
        if client is None or client not in ready:
            return
        try:
            data = client.recv(CHUNK)
        except BlockingIOError:
            return
        except OSError:
            data = b""
        if not data:
            with self._io_lock:
                if self._client is client:
                    self._drop_client()
            return
        self._put(data)

    def _write_some(self, view: memoryview) -> int | None:
        if self._client is None:
            return None
        try:
            return self._client.send(view)
        except BlockingIOError:
            return 0

    def _writable_fd(self) -> socket.socket | None:
        return self._client

    def _drop_client(self) -> None:
        if self._client is not None:
            self._client.close()
            self._client = None

    def _open_endpoint(self) -> bool:
        try:
            self._listener = self._listen(*self._address)
        except OSError as exc:
            logger.warning("%s: cannot listen again yet (%s)", self.url, exc)
            return False
        return True

    def _close_endpoint(self) -> None:
        self._drop_client()
        if self._listener is not None:
            self._listener.close()
            self._listener = None


def serve_pty(bus: VirtualBus, link: str | os.PathLike[str] | None = None) -> EmulatorServer:
    """Serve ``bus`` on a new pseudo-terminal.

    Args:
        bus: the virtual bus.
        link: optional symlink kept pointing at the pty (see :class:`PtyServer`).

    Returns:
        The running server; open ``server.url`` (e.g. ``/dev/pts/7``) with pyserial.

    Raises:
        PortError: the link cannot be made.
    """
    server = PtyServer(bus, link)
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
