"""Bus test helpers: virtual motors on the in-process link, a real pty or a TCP socket."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import AbstractContextManager, contextmanager
from typing import Any

from poppy_core.emulator import VirtualBus, build_bus_from_spec, serve_link, serve_pty, serve_tcp

Emulate = Callable[..., AbstractContextManager[tuple[VirtualBus, str]]]


@contextmanager
def emulate_bus(
    spec: str, *, via: str = "link", baudrate: int = 1_000_000, **options: Any
) -> Iterator[tuple[VirtualBus, str]]:
    """Serve ``spec`` (``via``: ``"link"``, ``"pty"`` or ``"tcp"``); yield the bus and its URL."""
    bus = build_bus_from_spec(spec, baudrate=baudrate, **options)
    servers = {"link": serve_link, "pty": serve_pty, "tcp": serve_tcp}
    with servers[via](bus) as server:
        yield bus, server.url
