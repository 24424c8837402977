"""TUI test helpers: a port lister that finds nothing, waiting in a pilot, running async tests."""

from __future__ import annotations

import asyncio
import functools
import time
from collections.abc import Callable, Coroutine
from typing import Any

from poppy_core.bus import PortInfo
from tests.helpers.waiting import MIN_TIMEOUT_S, scaled


def no_ports() -> list[PortInfo]:
    """A port lister that finds nothing (tests add virtual buses)."""
    return []


async def wait_for(
    pilot: object, check: Callable[[], bool], timeout_s: float = 10.0, what: str = ""
) -> None:
    """Let the app run until ``check()`` holds (fails the test after ``timeout_s``, at least
    ``MIN_TIMEOUT_S``, times the load factor: a wait is not a speed check)."""
    end = time.monotonic() + scaled(max(timeout_s, MIN_TIMEOUT_S))
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
