"""Fixtures for the bus tests: virtual motors on the in-process link, a real pty or a TCP socket."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import AbstractContextManager, contextmanager
from typing import Any

import pytest

from poppy_core.emulator import VirtualBus, build_bus_from_spec, serve_link, serve_pty, serve_tcp

Emulate = Callable[..., AbstractContextManager[tuple[VirtualBus, str]]]


@contextmanager
def _emulate(
    spec: str, *, via: str = "link", baudrate: int = 1_000_000, **options: Any
) -> Iterator[tuple[VirtualBus, str]]:
    bus = build_bus_from_spec(spec, baudrate=baudrate, **options)
    servers = {"link": serve_link, "pty": serve_pty, "tcp": serve_tcp}
    with servers[via](bus) as server:
        yield bus, server.url


@pytest.fixture
def emulate() -> Emulate:
    """``with emulate("MX-28:1-3", via="tcp") as (virtual_bus, url): ...`` (default: ``"link"``)."""
    return _emulate


@pytest.fixture(params=["link", "pty", "tcp"])
def via(request: pytest.FixtureRequest) -> str:
    """Run a test over the in-process link, a pty and socket://."""
    return str(request.param)
