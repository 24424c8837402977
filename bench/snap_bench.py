"""``python -m bench snap``: Snap! server throughput and latency, poppy's vs pypot's.

Both servers drive the same virtual Ergo Jr: ``poppy emulate --profile ergo-jr
--wire-timing`` (6 XL-320 on protocol 2, in its own process; one emulator per server, one
after the other). poppy runs ``poppy serve --snap --port PTY``; pypot runs its
``SnapRobotServer`` through ``PoppyErgoJr(config=..., use_snap=True)``
(``bench/peers/pypot_snap.py``). The load comes from wrk when installed, else Python threads
(see ``server_bench``).
"""

from __future__ import annotations

import http.client
import math
import os
import shutil
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from bench import side_by_side
from bench.emulator_proc import EmulatorProcess
from bench.procs import child, free_port
from bench.registry import POPPY_PYTHON, REPO_ROOT, BenchContext, BenchResult, Table, register
from bench.server_bench import CLIENTS, DURATION_S, _load, _load_wrk, _wait_listening
from bench.side_by_side import measure_sides, median, median_cells

SCENARIOS: dict[str, str] = {
    "GET /motors/get/positions": "/motors/get/positions",
    "set 3 motors (/motors/set/registers)": (
        "/motors/set/registers/m1:goal_position:10;m2:goal_position:-10;m3:goal_position:5"
    ),
}
GOAL_RATIO = 2.0
WARM_UP_REQUESTS = 200
PYPOT_SCRIPT = REPO_ROOT / "bench" / "peers" / "pypot_snap.py"


class ErgoJrEmulator(EmulatorProcess):
    """``poppy emulate --profile ergo-jr --wire-timing --latency-ms 1`` (return delays 0)."""

    def __init__(self) -> None:
        super().__init__("XL-320:1-6")
        self._args = [*self._args[:2], "--profile", "ergo-jr", *self._args[4:]]


@contextmanager
def _server(kind: str, ctx: BenchContext) -> Iterator[int]:
    port = free_port()
    with ErgoJrEmulator() as emulator, tempfile.TemporaryDirectory() as moves:
        if kind == "poppy":
            args = [str(POPPY_PYTHON), "-m", "poppy_cli", "serve", "--snap"]
            args += ["--profile", "ergo-jr", "--port", emulator.port, "--no-sensors"]
            args += ["--snap-port", str(port)]
        else:
            args = [str(ctx.peers_python), str(PYPOT_SCRIPT), "--port", emulator.port]
            args += ["--snap-port", str(port), "--moves-dir", moves]
        env = {"POPPY_MOVES_DIR": str(Path(moves) / "poppy")}
        with child(args, env=env) as proc:
            _wait_listening(port, proc)
            yield port


def _warm_up(port: int) -> None:
    """A few hundred requests first: the server's first answers (imports, caches) are not timed."""
    conn = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
    try:
        for _ in range(WARM_UP_REQUESTS):
            for path in SCENARIOS.values():
                conn.request("GET", path)
                conn.getresponse().read()
    finally:
        conn.close()


def _measure(kind: str, ctx: BenchContext) -> dict[str, Any]:
    out: dict[str, Any] = {}
    wrk = shutil.which("wrk")
    with _server(kind, ctx) as port:
        _warm_up(port)
        for name, path in SCENARIOS.items():
            runs = []
            for _ in range(ctx.repeat):
                if wrk is not None:
                    runs.append(_load_wrk(wrk, port, "GET", path, None))
                else:
                    runs.append(_load(port, "GET", path, None))
            runs.sort(key=lambda r: float(r["rps"]))
            out[name] = {"median": runs[len(runs) // 2], "runs": runs}
    return out


@register("snap", "Snap! server requests/s and p50/p99: poppy serve --snap vs pypot's")
def snap_bench(ctx: BenchContext) -> BenchResult:
    """Measure both Snap! servers on every scenario."""
    raw: dict[str, Any] = {"clients": CLIENTS, "duration_s": DURATION_S}
    load_start = os.getloadavg()[0]
    sides, notes = measure_sides(ctx, _measure, "Snap! server")
    raw.update(sides)
    rows: list[list[str]] = []
    verdicts: list[bool] = []
    for name in SCENARIOS:
        row = [name, *median_cells(raw, name)]
        mine, theirs = median(raw, "poppy", name), median(raw, "pypot", name)
        if mine is None or theirs is None or not theirs["rps"]:
            row += ["-", "-"]
        else:
            ratio = mine["rps"] / theirs["rps"]
            met = ratio >= GOAL_RATIO and mine["p99_s"] < theirs["p99_s"] and not mine["errors"]
            verdicts.append(met)
            row += [f"{ratio:.1f}x", "pass" if met else "**FAIL**"]
        rows.append(row)
    headers = side_by_side.headers()
    headers += ["poppy / pypot", f">= {GOAL_RATIO:g}x, lower p99"]
    wrk = shutil.which("wrk")
    notes.append(
        (
            f"Load: wrk, one thread, {CLIENTS} keep-alive connections"
            if wrk
            else f"Load: {CLIENTS} Python client threads with keep-alive connections"
        )
        + f", {math.ceil(DURATION_S) if wrk else DURATION_S} s per run, median of "
        f"{ctx.repeat} runs (by req/s). Each server drives its own `poppy emulate --profile "
        "ergo-jr --wire-timing --latency-ms 1` process."
        f" Machine load (1-minute average) at start and end: {load_start:.2f} → "
        f"{os.getloadavg()[0]:.2f} on {os.cpu_count()} cores: above about 1, other programs "
        "shared the CPU and the figures (p99 above all) vary from run to run."
    )
    return BenchResult(
        name="snap",
        title="Snap! server",
        intro=(
            "Requests per second and latency of the Snap! routes (plain-text GETs, as Snap!'s "
            "`reportURL` sends them) on a virtual Ergo Jr: poppy (`poppy serve --snap`) "
            "against pypot 5 (`PoppyErgoJr(use_snap=True)`, bottle on tornado), both on "
            "127.0.0.1 in their own process."
        ),
        tables=[Table("Snap! server", headers, rows)],
        notes=notes,
        passed=all(verdicts) if verdicts else None,
        raw=raw,
    )
