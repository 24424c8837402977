"""Serve a VirtualBus on a pseudo-terminal or a TCP socket: a reader thread and a responder thread.

The *reader* waits on the endpoint and takes instruction bytes off it as soon as they arrive,
stamping each chunk with its arrival time (and, on a pty, the line speed the client set); the
*responder* hands the chunks to the bus in order and writes each reply when it is due. Reading
never waits for a reply's wire timing, a plant step or a slow client, so arrival times are
exact and a client that writes while a reply is still held back is heard at once.

Replies are written whole: a pty or socket that cannot take a reply yet (the client is not
reading) is waited on; a reply that could not start within ``WRITE_TIMEOUT_S`` is dropped as a
whole, never cut.

Note on flush-happy clients (pypot flushes input and output before every packet): on Linux,
bytes written to a pty slave sit in a kernel buffer until a kernel worker moves them to the
master's side; a flush of the slave's output before that discards them, before any reader can
see them. It happens only when no CPU is free for that worker at that instant (see
docs/emulator.md); the emulator keeps its threads blocked while idle so that one is.
"""

from __future__ import annotations

import contextlib
import logging
import os
import queue
import select
import socket
import threading
import time
import tty
from abc import ABC, abstractmethod
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from types import TracebackType

from poppy_core.emulator.bus import Reply, VirtualBus
from poppy_core.emulator.linespeed import read_pty_baudrate
from poppy_core.emulator.timing import SPIN_WINDOW_S, sleep_until
from poppy_core.errors import PortError

logger = logging.getLogger(__name__)

_CHUNK = 4096
# How long a reply may wait for the client to make room before it is dropped (whole).
WRITE_TIMEOUT_S = 1.0
_WRITABLE_POLL_S = 0.05
_REBIND_RETRY_S = 0.5


@dataclass(frozen=True)
class _Chunk:
    """Instruction bytes as they came off the line."""

    data: bytes
    received_at: float
    line_bps: int | None


_RESET = "reset"  # a new client or a new line: forget partial instruction bytes and replies
_DUE = "due"  # (responder) no new bytes came before the first reply's due time
_Item = _Chunk | str | None


class EmulatorServer(ABC):
    """A running emulator endpoint; ``url`` is what a client opens with pyserial.

    Use :func:`serve_pty` or :func:`serve_tcp` to create one. Stop it with :meth:`stop` or a
    ``with`` block.

    Attributes:
        bus: the virtual bus being served.
        url: the pty slave path (``/dev/pts/N``) or ``socket://host:port``; a pty gets a new
            path after :meth:`lose` (its ``link``, when given, follows it).
        replies_dropped: replies dropped because the client did not read them in time or the
            line was down.
    """

    def __init__(self, bus: VirtualBus, url: str) -> None:
        self.bus = bus
        self.url = url
        self.replies_dropped = 0
        self._stop = threading.Event()
        self._wake_r, self._wake_w = os.pipe()
        os.set_blocking(self._wake_r, False)
        self._inbox: queue.SimpleQueue[_Item] = queue.SimpleQueue()
        self._io_lock = (
            threading.Lock()
        )  # the endpoint's descriptors: reader swaps, responder writes
        self._outage_s: float | None = None
        self._down = False
        self._reader = threading.Thread(
            target=self._guarded(self._read_loop), name=f"emulator reader {url}", daemon=True
        )
        self._thread = threading.Thread(
            target=self._guarded(self._respond_loop), name=f"emulator {url}", daemon=True
        )

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
        """True while the serving threads are alive."""
        return self._thread.is_alive() or self._reader.is_alive()

    @property
    def connected(self) -> bool:
        """False while the line is down (see :meth:`lose`)."""
        return not self._down

    def start(self) -> None:
        """Start the serving threads (the ``serve_*`` functions do it)."""
        self._thread.start()
        self._reader.start()

    def stop(self) -> None:
        """Stop serving, join the threads and close the endpoint (idempotent)."""
        if self._stop.is_set():
            return
        self._stop.set()
        self._wake()
        self._inbox.put(None)
        for thread in (self._reader, self._thread):
            if thread.is_alive() and thread is not threading.current_thread():
                thread.join(timeout=5.0)
        with self._io_lock:
            self._close_endpoint()
        os.close(self._wake_r)
        os.close(self._wake_w)

    def lose(self, duration_s: float) -> None:
        """Take the whole line away for ``duration_s`` seconds, then bring it back.

        As when a USB adapter is unplugged or a bridge goes down: the endpoint closes (a
        client's reads and writes fail, a pty's path and link disappear, a TCP port refuses
        connections), then a new one opens (a new pty, re-linked; the same TCP port).
        """
        if duration_s < 0:
            raise ValueError(f"duration must be >= 0, got {duration_s}")
        self._outage_s = float(duration_s)
        self._wake()

    # ------------------------------------------------------------------ threads

    def _guarded(self, loop: Callable[[], None]) -> Callable[[], None]:
        def run() -> None:
            try:
                loop()
            except Exception:
                logger.exception("emulator server %s crashed", self.url)

        return run

    def _wake(self) -> None:
        with contextlib.suppress(OSError):
            os.write(self._wake_w, b"\0")

    def _read_loop(self) -> None:
        while not self._stop.is_set():
            if self._outage_s is not None:
                duration, self._outage_s = self._outage_s, None
                self._outage(duration)
                continue
            watched = [self._wake_r, *self._watched()]
            try:
                ready, _, _ = select.select(watched, [], [])
            except (OSError, ValueError):  # a descriptor closed under us: look again
                continue
            if self._wake_r in ready:
                with contextlib.suppress(OSError):
                    os.read(self._wake_r, 64)
                continue
            self._on_readable(ready)

    def _outage(self, duration_s: float) -> None:
        with self._io_lock:
            self._down = True
            self._close_endpoint()
        self._inbox.put(_RESET)
        logger.info("%s: line down for %.1f s", self.url, duration_s)
        end = time.monotonic() + duration_s
        while not self._stop.wait(max(0.0, end - time.monotonic())):
            with self._io_lock:
                if self._open_endpoint():
                    self._down = False
                    break
            end = time.monotonic() + _REBIND_RETRY_S
        if not self._down:
            logger.info("%s: line back", self.url)

    def _put(self, data: bytes, line_bps: int | None = None) -> None:
        self._inbox.put(_Chunk(data, time.perf_counter(), line_bps))

    def _respond_loop(self) -> None:
        """Hand chunks to the bus as they come; write each reply when due, in order.

        Incoming bytes are dispatched even while a reply waits for its due time (a write sent
        meanwhile reaches its motor at once); replies leave in the order they were made.
        """
        pending: deque[Reply] = deque()
        while True:
            item: _Item | str
            if not pending:
                item = self._inbox.get()
            else:
                due = pending[0].send_at
                wait_s = due - time.perf_counter() - SPIN_WINDOW_S if due else 0.0
                try:
                    item = (
                        self._inbox.get(timeout=wait_s) if wait_s > 0 else self._inbox.get_nowait()
                    )
                except queue.Empty:
                    item = _DUE
            if item is None or self._stop.is_set():
                return
            if item == _DUE:
                reply = pending.popleft()
                if reply.send_at:
                    sleep_until(reply.send_at)
                data = reply.data
                # Replies due by now leave together, as an adapter hands them over in one USB
                # transfer: no gap between them for the host to take for the end.
                now = time.perf_counter()
                while pending and pending[0].send_at <= now:
                    data += pending.popleft().data
                self._send(data)
            elif item == _RESET:
                self.bus.reset_input()
                self.replies_dropped += len(pending)
                pending.clear()
            elif isinstance(item, _Chunk):
                pending.extend(
                    self.bus.receive(
                        item.data, line_bps=item.line_bps, received_at=item.received_at
                    )
                )

    def _send(self, data: bytes) -> None:
        """Write one reply whole (waiting for room), or drop it whole."""
        view = memoryview(data)
        give_up = time.monotonic() + WRITE_TIMEOUT_S
        while view and not self._stop.is_set():
            with self._io_lock:
                try:
                    written = self._write_some(view)
                except OSError as exc:
                    logger.debug("%s: write failed (%s)", self.url, exc)
                    written = None
                fd = self._writable_fd()
            if written is None:  # no client or the line is down
                break
            view = view[written:]
            if not view:
                return
            if written == 0 and len(view) == len(data) and time.monotonic() > give_up:
                break
            if fd is not None:
                with contextlib.suppress(OSError, ValueError):
                    select.select([], [fd], [], _WRITABLE_POLL_S)
        if view:
            self.replies_dropped += 1
            logger.debug("%s: reply of %d bytes dropped", self.url, len(data))

    # ------------------------------------------------------------------ endpoint

    @abstractmethod
    def _watched(self) -> list[int | socket.socket]:
        """What the reader waits on (besides its wake pipe)."""

    @abstractmethod
    def _on_readable(self, ready: list[int | socket.socket]) -> None:
        """Take what is ready off the endpoint and queue it (``_put``)."""

    @abstractmethod
    def _write_some(self, view: memoryview) -> int | None:
        """Write what the endpoint takes now: bytes written (0: full), None: no endpoint."""

    @abstractmethod
    def _writable_fd(self) -> int | socket.socket | None:
        """What to wait on for room to write."""

    @abstractmethod
    def _open_endpoint(self) -> bool:
        """Open a new endpoint after an outage; False to retry a little later."""

    @abstractmethod
    def _close_endpoint(self) -> None:
        """Release the endpoint's descriptors or sockets (idempotent)."""


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
            data = os.read(master, _CHUNK)
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
            self._inbox.put(_RESET)
            logger.debug("%s: client %s connected", self.url, peer)
        client = self._client
        if client is None or client not in ready:
            return
        try:
            data = client.recv(_CHUNK)
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
