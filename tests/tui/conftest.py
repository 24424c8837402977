"""Fixtures of the TUI tests: virtual buses linked in this process, helpers to wait in a pilot."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from poppy_core.emulator import Endpoint, build_bus_from_spec, serve_link
from tests.helpers.tui import no_ports, run_async, wait_for

__all__ = ["no_ports", "run_async", "wait_for"]


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
