"""In-process link: a ``VirtualBus`` reached at ``emu://NAME`` by a bus in the same interpreter.

When the robot and its virtual motors share a process there is no need for a pty and two
serving threads between them: :func:`serve_link` registers the bus under a name, and any
``Transport``/``DxlBus`` opening ``emu://NAME`` gets a :class:`VirtualLine` that hands the
instruction bytes to the bus in the writer's thread and gives each reply back once it is due
(``Reply.send_at``: the same wire timing rules as a pty; replies are immediate unless the bus
has ``wire_timing``, latency or a fault delay). The line speed the host set is the one motors
hear, so a scan at the wrong rate finds nothing, as on a pty.

Nothing here runs on its own: no thread to be scheduled on a loaded machine, so a reply is
never late because the emulator did not get the CPU. Other programs (pypot, the Dynamixel SDK,
another ``poppy``) still need :func:`serve_pty` or :func:`serve_tcp`.
"""

from __future__ import annotations

import itertools
import logging
import threading
import time
from collections import deque

from poppy_core.emulator.bus import Reply, VirtualBus
from poppy_core.errors import PortError
from poppy_core.line import Line, register_scheme

__all__ = ["SCHEME", "LinkServer", "VirtualLine", "serve_link"]

logger = logging.getLogger(__name__)

SCHEME = "emu"
_names = itertools.count(1)
_servers: dict[str, LinkServer] = {}
_servers_lock = threading.Lock()


class LinkServer:
    """A ``VirtualBus`` offered at ``emu://NAME`` in this process (see the module docstring).

    It has the same face as an ``EmulatorServer`` (``bus``, ``url``, ``stop``, ``lose``,
    ``connected``, ``replies_dropped``), so fault control and ``robot.emulators`` treat both
    alike. Create it with :func:`serve_link`.
    """

    def __init__(self, bus: VirtualBus, name: str) -> None:
        self.bus = bus
        self.url = f"{SCHEME}://{name}"
        self.replies_dropped = 0
        self._name = name
        self._stopped = False
        self._down_until = 0.0
        self._generation = 0
        self._lock = threading.Lock()

    def __enter__(self) -> LinkServer:
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()

    def __repr__(self) -> str:
        return f"LinkServer({self.url!r})"

    @property
    def running(self) -> bool:
        """True until :meth:`stop`."""
        return not self._stopped

    @property
    def connected(self) -> bool:
        """False while the line is down (see :meth:`lose`)."""
        return not self._stopped and time.monotonic() >= self._down_until

    def stop(self) -> None:
        """Stop serving: open lines fail, the URL no longer opens (idempotent)."""
        with self._lock:
            self._stopped = True
            self._generation += 1
        with _servers_lock:
            if _servers.get(self._name) is self:
                del _servers[self._name]

    def lose(self, duration_s: float) -> None:
        """Take the line away for ``duration_s`` seconds, as when an adapter is unplugged.

        Open lines fail from now on (a bus reopens the URL once it is back); opening fails
        until the time is up.
        """
        if duration_s < 0:
            raise ValueError(f"duration must be >= 0, got {duration_s}")
        with self._lock:
            self._generation += 1
            self._down_until = time.monotonic() + duration_s
        logger.info("%s: line down for %.1f s", self.url, duration_s)

    def open(self, baudrate: int) -> VirtualLine:
        """A new line to the bus at ``baudrate`` (what ``emu://NAME`` opens).

        Raises:
            PortError: the server is stopped or the line is down.
        """
        with self._lock:
            if not self.connected:
                raise PortError(
                    f"nothing answers at {self.url}: the emulator is stopped or its line is down",
                    port=self.url,
                )
            generation = self._generation
        self.bus.reset_input()
        return VirtualLine(self, generation, baudrate)

    def alive(self, generation: int) -> bool:
        """Whether a line opened at ``generation`` still works."""
        return generation == self._generation and self.connected


class VirtualLine(Line):
    """The host's end of an in-process link (a :class:`~poppy_core.line.Line`)."""

    def __init__(self, server: LinkServer, generation: int, baudrate: int) -> None:
        self.port = server.url
        self._server = server
        self._generation = generation
        self._baudrate = baudrate
        self._open = True
        self._pending: deque[Reply] = deque()
        self._ready = threading.Condition()

    @property
    def baudrate(self) -> int:
        """Line speed in bit/s (what the motors must be set to, to hear the host)."""
        return self._baudrate

    def set_baudrate(self, baudrate: int) -> None:
        """Change the line speed."""
        if baudrate <= 0:
            raise PortError(f"cannot set {self.port} to {baudrate} bps", port=self.port)
        self._baudrate = baudrate

    @property
    def is_open(self) -> bool:
        """True until ``close``."""
        return self._open

    def _check(self, doing: str) -> None:
        if not self._open:
            raise PortError(f"{self.port} is closed", port=self.port)
        if not self._server.alive(self._generation):
            raise PortError(f"lost {self.port} while {doing}: the line went down", port=self.port)

    def write(self, data: bytes) -> None:
        """Hand instruction bytes to the bus; its replies wait here until due.

        Raises:
            PortError: the line is closed or went down.
        """
        self._check("writing")
        replies = self._server.bus.receive(
            bytes(data), line_bps=self._baudrate, received_at=time.perf_counter()
        )
        if replies:
            with self._ready:
                self._pending.extend(replies)
                self._ready.notify_all()

    def read(self, wait_s: float | None) -> bytes:
        """Wait up to ``wait_s`` (None: forever) for replies due by now; return their bytes.

        Raises:
            PortError: the line is closed or went down.
        """
        end = None if wait_s is None else time.perf_counter() + wait_s
        with self._ready:
            while True:
                self._check("reading")
                now = time.perf_counter()
                data = b""
                while self._pending and self._pending[0].send_at <= now:
                    data += self._pending.popleft().data
                if data:
                    return data
                wake = self._pending[0].send_at if self._pending else None
                if end is not None:
                    if now >= end:
                        return b""
                    wake = end if wake is None else min(wake, end)
                self._ready.wait(None if wake is None else max(0.0, wake - now))

    def reset_input(self) -> None:
        """Drop replies not read yet (due or not)."""
        with self._ready:
            self._server.replies_dropped += len(self._pending)
            self._pending.clear()

    def close(self) -> None:
        """Close this end (idempotent); the server keeps serving."""
        self._open = False
        with self._ready:
            self._pending.clear()
            self._ready.notify_all()


def _open(url: str, baudrate: int) -> Line:
    name = url.partition("://")[2]
    with _servers_lock:
        server = _servers.get(name)
    if server is None:
        raise PortError(
            f"no emulator at {url} in this process: start one with serve_link", port=url
        )
    return server.open(baudrate)


def serve_link(bus: VirtualBus, name: str | None = None) -> LinkServer:
    """Offer ``bus`` in this process at ``emu://NAME``.

    Args:
        bus: the virtual bus.
        name: the URL's name; None picks a free one (``emu://1``, ``emu://2``...).

    Returns:
        The server; open ``server.url`` with ``DxlBus``/``Transport`` in this process.

    Raises:
        PortError: ``name`` is already served.
    """
    register_scheme(SCHEME, _open)
    with _servers_lock:
        if name is None:
            name = next(n for n in map(str, _names) if n not in _servers)
        if name in _servers:
            raise PortError(f"{SCHEME}://{name} is already served", port=f"{SCHEME}://{name}")
        server = LinkServer(bus, name)
        _servers[name] = server
    return server
