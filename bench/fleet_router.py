"""``bench fleet`` through a router: a `poppy fleet router` process on loopback, and the table
that sets its figures beside the same run's peer-to-peer ones."""

from __future__ import annotations

import os
import subprocess
import sys
from types import TracebackType
from typing import Any

from bench.procs import free_port, interrupt
from bench.registry import POPPY_PYTHON, REPO_ROOT, Table


class RouterProcess:
    """`poppy fleet router --listen tcp/127.0.0.1:PORT` while in the ``with``."""

    def __init__(self) -> None:
        self.endpoint = f"tcp/127.0.0.1:{free_port()}"
        self.proc: subprocess.Popen[str] | None = None

    def __enter__(self) -> RouterProcess:
        python = str(POPPY_PYTHON) if POPPY_PYTHON.exists() else sys.executable
        self.proc = subprocess.Popen(
            [python, "-m", "poppy_cli", "fleet", "router", "--listen", self.endpoint],
            cwd=REPO_ROOT,
            stdout=subprocess.PIPE,
            text=True,
            env={**os.environ, "PYTHONPATH": str(REPO_ROOT)},
        )
        assert self.proc.stdout is not None
        if "listening on" not in self.proc.stdout.readline():
            raise RuntimeError("the router did not start")
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        error: BaseException | None,
        trace: TracebackType | None,
    ) -> None:
        if self.proc is not None:
            interrupt(self.proc)
            if self.proc.stdout is not None:
                self.proc.stdout.close()


def router_table(raw: dict[str, Any]) -> Table:
    """Peer to peer against through a router, from the same run."""
    rows = []
    for label, z, play, cpu_play in (
        ("peer to peer", raw["zenoh"], raw["play"], None),
        (
            "through `poppy fleet router`",
            raw["router"]["zenoh"],
            raw["router"]["play"],
            raw["router"]["play_router_cpu_pct"],
        ),
    ):
        rows.append(
            [
                label,
                f"{_fmt(z['rate_min_hz'])} / {_fmt(z['rate_median_hz'])}",
                f"{_fmt(z['age_p50_ms'], 2)} / {_fmt(z['age_p99_ms'], 2)}",
                f"{_fmt(play['run']['spread_p99_ms'], 2)} / "
                f"{_fmt(play['run']['spread_max_ms'], 2)}",
                f"{_fmt(play['play']['spread_p99_ms'], 2)} / "
                f"{_fmt(play['play']['spread_max_ms'], 2)}",
                f"{_fmt(z.get('router_cpu_pct'))} / {_fmt(cpu_play)}",
            ]
        )
    return Table(
        "20 robots at 50 Hz: peer to peer against through a router (same run)",
        [
            "topology",
            "state rate min / median (Hz)",
            "state age p50 / p99 (ms)",
            "`fleet run` spread p99 / max (ms)",
            "`fleet play` spread p99 / max (ms)",
            "router CPU, fan-out / starts (% of a core)",
        ],
        rows,
    )


def router_passed(raw: dict[str, Any]) -> bool:
    """The issue's goals through the router: state age p99 < 10 ms, start spread < 20 ms."""
    found = raw["router"]
    return found["zenoh"]["age_p99_ms"] < 10.0 and all(
        found["play"][what]["spread_max_ms"] < 20.0 for what in ("run", "play")
    )


def _fmt(value: Any, digits: int = 1) -> str:
    return "-" if value is None else f"{value:.{digits}f}"
