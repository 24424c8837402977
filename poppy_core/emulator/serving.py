"""EmulatorServer: serving a VirtualBus with a reader thread and a responder thread.

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
from abc import ABC, abstractmethod
from collections import deque
from dataclasses import dataclass

from poppy_core.emulator.bus import Reply, VirtualBus
from poppy_core.emulator.wire_timing import SPIN_WINDOW_S, sleep_until
from poppy_core.schedule import Worker

logger = logging.getLogger(__name__)

CHUNK = 4096
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


RESET = "reset"  # a new client or a new line: forget partial instruction bytes and replies
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
        # Both loops end on ``_stop`` (shared: ``stop`` wakes the reader's select and the
        # responder's queue), not on their workers' own events.
        self._reader = Worker(f"emulator reader {url}", lambda _: self._read_loop())
        self._thread = Worker(f"emulator {url}", lambda _: self._respond_loop())

    def __enter__(self) -> EmulatorServer:
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.url!r})"

    @property
    def running(self) -> bool:
        """True while the serving threads are alive."""
        return self._thread.running or self._reader.running

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
        for worker in (self._reader, self._thread):
            worker.close(5.0)  # joins (but from its own thread); an error was logged once
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
        self._inbox.put(RESET)
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
            elif item == RESET:
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
