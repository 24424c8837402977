"""Fixtures of the fleet tests: two robots served on Zenoh and a fleet client of both."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from poppy_core.remote.zenoh_fleet import DEFAULT_TIMEOUT_S, Fleet
from poppy_core.zenoh_wire import ZenohSettings as Settings
from tests.helpers.waiting import scaled
from tests.helpers.zenoh_router import Router
from tests.helpers.zenoh_served import TOKEN, Served, connect_to


@pytest.fixture
def moves(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("POPPY_MOVES_DIR", str(tmp_path))
    return tmp_path


@pytest.fixture(scope="module")
def router() -> Iterator[Router]:
    """One router process for a module's tests (a process start each was most of their setup):
    it keeps nothing of a test's robots once their sessions close. A test that stops or
    restarts its router starts one of its own."""
    pytest.importorskip("zenoh")
    started = Router()
    try:
        yield started
    finally:
        started.kill()


@pytest.fixture
def two(moves: Path) -> Iterator[tuple[Served, Served]]:
    pytest.importorskip("zenoh")
    a, b = Served("jr-a"), Served("jr-b")
    try:
        yield a, b
    finally:
        a.close()
        b.close()


@pytest.fixture
def fleet(two: tuple[Served, Served]) -> Iterator[Fleet]:
    # its answers wait the product's timeout times the load factor: a loaded machine answered
    # a start after it once (both outcomes "no answer")
    timeout_s = scaled(DEFAULT_TIMEOUT_S)
    with Fleet(Settings(connect=connect_to(*two)), token=TOKEN, timeout_s=timeout_s) as client:
        assert client.wait_for(["jr-a", "jr-b"]) == ["jr-a", "jr-b"]
        yield client
