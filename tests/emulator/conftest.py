"""Fixtures for emulator tests: served buses and a tiny raw-bytes client over pyserial."""

from __future__ import annotations

from collections.abc import Iterator

import pytest
from emulator_client import RawClient

from poppy_core.emulator import VirtualBus, build_bus_from_spec
from tests.helpers.bus import client_on_pty


@pytest.fixture
def xl320_bus() -> VirtualBus:
    """Ergo Jr-like bus: XL-320 ids 1-3, protocol 2, 1 Mbps."""
    return build_bus_from_spec("XL-320:1-3", protocol=2, baudrate=1_000_000)


@pytest.fixture
def xl320(xl320_bus: VirtualBus) -> Iterator[RawClient]:
    with client_on_pty(xl320_bus, lambda s: RawClient(s.url, 2)) as client:
        yield client


@pytest.fixture
def mx_bus() -> VirtualBus:
    """Protocol 1 bus with MX-28 ids 11-13 and AX-12A 36, at 1 Mbps."""
    return build_bus_from_spec("MX-28:11-13,AX-12A:36", protocol=1, baudrate=1_000_000)


@pytest.fixture
def mx(mx_bus: VirtualBus) -> Iterator[RawClient]:
    with client_on_pty(mx_bus, lambda s: RawClient(s.url, 1)) as client:
        yield client


@pytest.fixture
def x_bus() -> VirtualBus:
    """X-series bus: XM430-W350 ids 1-3, protocol 2, 1 Mbps."""
    return build_bus_from_spec("XM430-W350:1-3", protocol=2, baudrate=1_000_000)


@pytest.fixture
def xm(x_bus: VirtualBus) -> Iterator[RawClient]:
    with client_on_pty(x_bus, lambda s: RawClient(s.url, 2)) as client:
        yield client
