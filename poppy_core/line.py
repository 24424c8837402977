"""The byte-line contract under every bus (``Line``) and the table of URL schemes that open one.

A ``Line`` moves raw bytes and nothing else; ``poppy_core.bus.Transport`` (decoding, deadlines)
sits on any line, so every timing rule of the bus is the same whatever carries the bytes. The
model is httpx's ``BaseTransport``/``MockTransport``: one small protocol, a real implementation
(``poppy_core.bus.SerialLine``: a device, a pty, ``socket://``, ``loop://``) and others plugged
in by URL scheme: the emulator registers ``emu`` for its in-process link
(``poppy_core.emulator.link``). This module is a leaf (bus and emulator both import it, neither
imports the other); the scheme table is its one piece of process-wide state, as pyserial's
``protocol_handler_packages`` is.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Protocol, runtime_checkable

__all__ = ["Line", "LineOpener", "opener_for", "register_scheme", "scheme_of"]


@runtime_checkable
class Line(Protocol):
    """A half-duplex serial line seen from the host: bytes out, bytes in, a line speed.

    Every method raises ``PortError`` when the line went away (adapter unplugged, server
    stopped); a line never raises anything else for I/O.
    """

    port: str

    @property
    def baudrate(self) -> int:
        """Line speed in bit/s."""
        ...

    def set_baudrate(self, baudrate: int) -> None:
        """Change the line speed."""
        ...

    @property
    def is_open(self) -> bool:
        """True until ``close``."""
        ...

    def write(self, data: bytes) -> None:
        """Send ``data`` whole."""
        ...

    def read(self, wait_s: float | None) -> bytes:
        """Wait up to ``wait_s`` seconds (None: forever) for bytes; return what arrived (or b"")."""
        ...

    def reset_input(self) -> None:
        """Drop every byte received and not read yet."""
        ...

    def close(self) -> None:
        """Close the line (idempotent)."""
        ...


LineOpener = Callable[[str, int], Line]
"""Opens a line from its URL and a baud rate; raises ``PortError``."""

_schemes: dict[str, LineOpener] = {}
_schemes_lock = threading.Lock()


def register_scheme(scheme: str, opener: LineOpener) -> None:
    """Open URLs ``scheme://...`` with ``opener`` (instead of pyserial). Idempotent."""
    with _schemes_lock:
        _schemes[scheme] = opener


def scheme_of(port: str) -> str | None:
    """The URL scheme of ``port`` (``"socket"``, ``"emu"``), or None for a device path."""
    scheme, sep, _ = port.partition("://")
    return scheme if sep else None


def opener_for(port: str) -> LineOpener | None:
    """The opener registered for ``port``'s scheme, or None (a device path, a pyserial URL)."""
    scheme = scheme_of(port)
    if scheme is None:
        return None
    with _schemes_lock:
        return _schemes.get(scheme)
