"""Fixtures for the bus tests: virtual motors served on a real pty or a TCP socket."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import AbstractContextManager, contextmanager
from typing import Any

import pytest

from poppy_core.emulator import VirtualBus, build_bus_from_spec, serve_pty, serve_tcp

Emulate = Callable[..., AbstractContextManager[tuple[VirtualBus, str]]]


@contextmanager
def _emulate(
    spec: str, *, via: str = "pty", baudrate: int = 1_000_000, **options: Any
) -> Iterator[tuple[VirtualBus, str]]:
    bus = build_bus_from_spec(spec, baudrate=baudrate, **options)
    server = serve_pty(bus) if via == "pty" else serve_tcp(bus)
    with server:
        yield bus, server.url


@pytest.fixture
def emulate() -> Emulate:
    """``with emulate("MX-28:1-3", via="tcp") as (virtual_bus, url): ...``."""
    return _emulate


@pytest.fixture(params=["pty", "tcp"])
def via(request: pytest.FixtureRequest) -> str:
    """Run a test over a pty and over socket://."""
    return str(request.param)
