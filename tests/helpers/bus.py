"""Bus test helpers: virtual motors on the in-process link, a real pty or a TCP socket."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import AbstractContextManager, contextmanager
from typing import Any, Protocol, TypeVar

import pytest

from poppy_core.bus import DxlBus
from poppy_core.emulator import (
    EmulatorServer,
    VirtualBus,
    build_bus_from_spec,
    serve_link,
    serve_pty,
    serve_tcp,
)
from poppy_core.robot import build_steps
from tests.helpers.waiting import LOADED_REPLY_FLOOR_IDLE_S, scaled


# The first-reply floor for a DxlBus whose other end is an emulator thread of the test process on
# a pty: the bus's own floor (MIN_REPLY_TIMEOUT_S, 10 ms) is a real adapter's, and a busy machine
# (two busy loops and more on two cores) runs that thread tens of milliseconds late now and then.
# A test that checks what the replies say, not how fast they come, gives its bus this floor; it
# costs nothing while the motors answer. Half a second on an idle machine, times the load factor
# measured when the bus is made. The `poppy` commands a test runs get the same floor through
# POPPY_REPLY_FLOOR_S (``tests.helpers.waiting.reply_floor_env``).
def loaded_reply_floor_s() -> float:
    """``LOADED_REPLY_FLOOR_IDLE_S`` times the load factor measured now (not at import: the
    workers import every module while collecting, the busiest seconds of a run)."""
    return scaled(LOADED_REPLY_FLOOR_IDLE_S)


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


class _Closable(Protocol):
    def close(self) -> None: ...


C = TypeVar("C", bound=_Closable)


@contextmanager
def client_on_pty(bus: VirtualBus, open_client: Callable[[EmulatorServer], C]) -> Iterator[C]:
    """Serve ``bus`` on a pty and yield the client ``open_client(server)`` opened (closed after)."""
    with serve_pty(bus) as server:
        client = open_client(server)
        try:
            yield client
        finally:
            client.close()


def robot_buses_wait_for_a_loaded_emulator(monkeypatch: pytest.MonkeyPatch) -> None:
    """Robots built in this test open their buses with ``loaded_reply_floor_s()`` as their
    first-reply floor: for robots whose motors are an emulator thread of the test process on a
    pty or TCP (a busy machine runs it late; the real adapter's 10 ms floor would take a late
    reply for a missing motor, or a motor that stopped answering). A test of the deadlines
    themselves does not use it."""

    class LoadedBus(DxlBus):
        def __init__(self, *args: Any, **options: Any) -> None:
            options.setdefault("min_timeout_s", loaded_reply_floor_s())
            super().__init__(*args, **options)

    monkeypatch.setattr(build_steps, "DxlBus", LoadedBus)
