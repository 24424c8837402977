"""Fixtures of the TUI tests: virtual buses linked in this process, helpers to wait in a pilot."""

from __future__ import annotations

import asyncio
import functools
import time
from collections.abc import Callable, Coroutine, Iterator
from typing import Any

import pytest

from poppy_core.bus import PortInfo
from poppy_core.emulator import Endpoint, build_bus_from_spec, serve_link


def no_ports() -> list[PortInfo]:
    """A port lister that finds nothing (tests add virtual buses)."""
    return []


@pytest.fixture
def xl320_server() -> Iterator[Endpoint]:
    """Three XL-320 (ids 1-3, protocol 2, 1 Mbps) at ``emu://N``."""
    server = serve_link(build_bus_from_spec("XL-320:1-3", protocol=2, baudrate=1_000_000))
    yield server
    server.stop()


@pytest.fixture
def big_server() -> Iterator[Endpoint]:
    """25 MX-28 (ids 1-25, protocol 1, 1 Mbps) at ``emu://N``."""
    server = serve_link(build_bus_from_spec("MX-28:1-25", protocol=1, baudrate=1_000_000))
    yield server
    server.stop()


async def wait_for(
    pilot: object, check: Callable[[], bool], timeout_s: float = 10.0, what: str = ""
) -> None:
    """Let the app run until ``check()`` holds (fails the test after ``timeout_s``)."""
    end = time.monotonic() + timeout_s
    while not check():
        if time.monotonic() > end:
            raise AssertionError(f"timed out waiting for {what or check}")
        await asyncio.sleep(0.02)


def run_async(test: Callable[..., Coroutine[Any, Any, None]]) -> Callable[..., None]:
    """Run an async test with asyncio.run (no async pytest plugin is installed)."""

    @functools.wraps(test)
    def wrapper(*args: Any, **kwargs: Any) -> None:
        asyncio.run(test(*args, **kwargs))

    return wrapper
