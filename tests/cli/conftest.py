"""Fixtures: `poppy` run in the test process against `poppy emulate` processes."""

from __future__ import annotations

import signal
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

import pytest

from poppy_core.emulator import VirtualBus
from tests.helpers.bus import emulate_bus
from tests.helpers.cli import POPPY, Result, run_poppy
from tests.helpers.processes import start
from tests.helpers.waiting import scaled

__all__ = ["POPPY", "Result", "run_poppy"]


class Emulator:
    """A `poppy emulate` process; `url` is the first line it printed."""

    def __init__(self, *args: str) -> None:
        self.proc = start([*POPPY, "emulate", *args])
        assert self.proc.stdout is not None
        line = self.proc.stdout.readline().strip()
        if not line:
            raise RuntimeError(f"poppy emulate printed nothing: {self.proc.stderr.read()}")
        self.url = line

    def stop(self, signum: int = signal.SIGINT) -> int:
        if self.proc.poll() is None:
            self.proc.send_signal(signum)
        code = self.proc.wait(timeout=scaled(10))
        for stream in (self.proc.stdout, self.proc.stderr):
            if stream is not None:
                stream.close()
        return code


@pytest.fixture
def poppy() -> Any:
    """Run `poppy ARGS...` (in this process, as a fresh one would): ``poppy("scan", "--json")``."""
    return run_poppy


@pytest.fixture
def emulator_factory() -> Iterator[Any]:
    started: list[Emulator] = []

    def start(*args: str) -> Emulator:
        emulator = Emulator(*args)
        started.append(emulator)
        return emulator

    yield start
    for emulator in started:
        emulator.stop()


@dataclass
class LinkedBus:
    """Virtual motors in this process, at ``url`` (``emu://NAME``) for an in-process `poppy`."""

    bus: VirtualBus
    url: str


@pytest.fixture
def ergo_jr() -> Iterator[LinkedBus]:
    """A virtual Ergo Jr bus (six XL-320, ids 1-6, protocol 2, 1 Mbps) on the in-process link."""
    with emulate_bus("XL-320:1-6", protocol=2) as (bus, url):
        yield LinkedBus(bus, url)


@pytest.fixture
def mx_bus() -> Iterator[LinkedBus]:
    """Three MX-28 (ids 11-13) and one AX-12A (36), protocol 1, 1 Mbps, on the in-process link."""
    with emulate_bus("MX-28:11-13,AX-12A:36", protocol=1) as (bus, url):
        yield LinkedBus(bus, url)
