"""Fixtures for the bus tests: virtual motors on the in-process link, a real pty or a TCP socket."""

from __future__ import annotations

import pytest

from tests.helpers.bus import Emulate, emulate_bus

__all__ = ["Emulate"]


@pytest.fixture
def emulate() -> Emulate:
    """``with emulate("MX-28:1-3", via="tcp") as (virtual_bus, url): ...`` (default: ``"link"``)."""
    return emulate_bus


@pytest.fixture(params=["link", "pty", "tcp"])
def via(request: pytest.FixtureRequest) -> str:
    """Run a test over the in-process link, a pty and socket://."""
    return str(request.param)
