"""``python -m bench server``: REST throughput and latency, poppy's server vs pypot's.

Both servers run in their own process on 127.0.0.1 over a virtual Ergo Jr (poppy: ``poppy
serve --http --sim``; pypot: ``PoppyErgoJr(simulator="dummy", use_http=True)``). The load comes
from wrk (a C load generator, one thread, ``CLIENTS`` keep-alive connections) when it is
installed (Debian package ``wrk``; ``bench/setup_peers.sh`` installs it when run as root), else
from ``CLIENTS`` threads of this process, each with one keep-alive ``http.client`` connection —
a Python client whose own cost caps the rate it can measure (about 9,000 requests/s here).
With ``--baseline DIR`` the poppy of another checkout is served beside this one and each run of
one is followed by the same run of the other, the order swapping each round (see
bench/server_baseline.py).
"""

from __future__ import annotations

import http.client
import json
import math
import os
import shutil
import socket
import subprocess
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

from bench import side_by_side
from bench.procs import child, free_port, served_ergo
from bench.registry import BenchContext, BenchResult, Table, register
from bench.scan_baseline import BASELINE_CLIENT, baseline_label
from bench.server_baseline import baseline_cpu_table, baseline_rps_table, calls_table
from bench.server_cpu import (
    background_cpu,
    call_counts,
    cpu_per_request,
    net_of_background,
    thread_cpu_ns,
)
from bench.side_by_side import measure_sides, median_cells, percentile

CLIENTS = 4
DURATION_S = 1.5
REQUEST_TIMEOUT_S = 5.0
GOTO_S = 1.0
START_TIMEOUT_S = 60.0

PYPOT_SERVER = """
import sys, time
import pypot.creatures
from poppy_ergo_jr import PoppyErgoJr
port = int(sys.argv[1])
robot = PoppyErgoJr(simulator="dummy", use_http=True, http_host="127.0.0.1", http_port=port)
print("ready", flush=True)
try:
    while True:
        time.sleep(1)
except KeyboardInterrupt:
    robot.close()
"""

REGISTER = "/motors/m1/registers/present_position/value.json"
SCENARIOS: dict[str, tuple[str, str, bytes | None]] = {
    "register GET": ("GET", REGISTER, None),
    "/robot.json": ("GET", "/robot.json", None),
    "goal POST": ("POST", "/motors/m1/registers/goal_position/value.json", b"10"),
    "register GET during a wait goto": ("GET", REGISTER, None),
}


def _wait_listening(port: int, proc: subprocess.Popen[str]) -> None:
    deadline = time.monotonic() + START_TIMEOUT_S
    while time.monotonic() < deadline:
        if proc.poll() is not None:
            raise RuntimeError(f"the server exited: {proc.stderr.read() if proc.stderr else ''}")
        try:
            with socket.create_connection(("127.0.0.1", port), timeout=0.5):
                return
        except OSError:
            time.sleep(0.1)
    raise RuntimeError("the server did not listen in time")


@contextmanager
def _server(kind: str, ctx: BenchContext) -> Iterator[tuple[int, int]]:
    """``kind``: "poppy", "pypot", or BASELINE_CLIENT (poppy run from the --baseline checkout)."""
    port = free_port()
    flags = ("--http", "--http-port", str(port))
    if kind == BASELINE_CLIENT and ctx.baseline is not None:  # its poppy_core first
        args = served_ergo("poppy", ctx, PYPOT_SERVER, port, *flags)
        where: dict[str, Any] = {"cwd": ctx.baseline, "env": {"PYTHONPATH": str(ctx.baseline)}}
    else:
        args, where = served_ergo(kind, ctx, PYPOT_SERVER, port, *flags), {}
    with child(args, **where) as proc:
        _wait_listening(port, proc)
        yield port, proc.pid


def _load(port: int, method: str, path: str, body: bytes | None) -> dict[str, Any]:
    latencies: list[float] = []
    errors = [0]
    lock = threading.Lock()
    end = time.monotonic() + DURATION_S

    def client() -> None:
        conn = http.client.HTTPConnection("127.0.0.1", port, timeout=REQUEST_TIMEOUT_S)
        mine: list[float] = []
        while time.monotonic() < end:
            t0 = time.perf_counter()
            try:
                conn.request(method, path, body, {"Content-Type": "application/json"})
                response = conn.getresponse()
                response.read()
                ok = response.status < 400
            except (OSError, http.client.HTTPException):
                conn.close()
                conn = http.client.HTTPConnection("127.0.0.1", port, timeout=REQUEST_TIMEOUT_S)
                ok = False
            if ok:
                mine.append(time.perf_counter() - t0)
            else:
                with lock:
                    errors[0] += 1
        conn.close()
        with lock:
            latencies.extend(mine)

    t0 = time.monotonic()
    threads = [threading.Thread(target=client) for _ in range(CLIENTS)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    elapsed = time.monotonic() - t0
    latencies.sort()

    return {
        "requests": len(latencies),
        "errors": errors[0],
        "rps": len(latencies) / elapsed,
        "p50_s": percentile(latencies, 0.5),
        "p99_s": percentile(latencies, 0.99),
    }


WRK_SCRIPT = """
wrk.method = "{method}"
wrk.headers["Content-Type"] = "application/json"
{body}
"""
_UNITS = {"us": 1e-6, "ms": 1e-3, "s": 1.0, "m": 60.0}


def _seconds(text: str) -> float:
    number = text.rstrip("usm")
    return float(number) * _UNITS[text[len(number) :]]


def _load_wrk(wrk: str, port: int, method: str, path: str, body: bytes | None) -> dict[str, Any]:
    """Load with wrk (a C load generator: one thread, CLIENTS keep-alive connections)."""
    import tempfile

    lua_body = f"wrk.body = {json.dumps(body.decode())}" if body else ""
    with tempfile.NamedTemporaryFile("w", suffix=".lua", delete=False) as script:
        script.write(WRK_SCRIPT.format(method=method, body=lua_body))
    try:
        out = subprocess.run(
            [
                wrk,
                "-t1",
                f"-c{CLIENTS}",
                f"-d{math.ceil(DURATION_S)}s",  # wrk takes whole seconds
                "--latency",
                "-s",
                script.name,
                f"http://127.0.0.1:{port}{path}",
            ],
            capture_output=True,
            text=True,
            timeout=DURATION_S + 30,
            check=True,
        ).stdout
    finally:
        os.unlink(script.name)
    result: dict[str, Any] = {"errors": 0, "client": "wrk"}
    for line in out.splitlines():
        words = line.split()
        if line.startswith("Requests/sec:"):
            result["rps"] = float(words[1])
        elif len(words) == 2 and words[0] in ("50%", "99%"):
            result["p50_s" if words[0] == "50%" else "p99_s"] = _seconds(words[1])
        elif "requests in" in line:
            result["requests"] = int(words[0])
        elif line.strip().startswith("Non-2xx or 3xx responses:"):
            result["errors"] += int(words[-1])
        elif line.strip().startswith("Socket errors:"):
            result["errors"] += sum(int(w.rstrip(",")) for w in words if w.rstrip(",").isdigit())
    return result


def _goto_loop(port: int, stop: threading.Event) -> None:
    body = json.dumps({"motors": ["m2"], "positions": [20], "duration": GOTO_S, "wait": True})
    conn = http.client.HTTPConnection("127.0.0.1", port, timeout=GOTO_S + REQUEST_TIMEOUT_S)
    while not stop.is_set():
        try:
            conn.request("POST", "/motors/goto.json", body, {"Content-Type": "application/json"})
            conn.getresponse().read()
        except (OSError, http.client.HTTPException):
            conn.close()
            conn = http.client.HTTPConnection("127.0.0.1", port, timeout=GOTO_S + 5)
    conn.close()


def _run(port: int, name: str, pid: int | None = None) -> dict[str, Any]:
    """One run of scenario ``name`` on the server at ``port``, with the load average at start
    and, given the server's ``pid``, the CPU it spent per request (``server_cpu``)."""
    method, path, body = SCENARIOS[name]
    wrk = shutil.which("wrk")
    load1 = os.getloadavg()[0]
    stop = threading.Event()
    mover = None
    if "goto" in name:
        mover = threading.Thread(target=_goto_loop, args=(port, stop))
        mover.start()
        time.sleep(0.1)
    try:
        idle_ns_per_s = background_cpu(pid) if pid is not None else 0.0
        before = thread_cpu_ns(pid) if pid is not None else {}
        t0 = time.monotonic()
        if wrk is not None:
            result = _load_wrk(wrk, port, method, path, body)
        else:
            result = _load(port, method, path, body)
        if pid is not None:
            background = idle_ns_per_s * (time.monotonic() - t0)
            spent = cpu_per_request(before, thread_cpu_ns(pid), result.get("requests", 0))
            result.update(spent, **net_of_background(spent, background, result.get("requests", 0)))
    finally:
        stop.set()
        if mover is not None:
            mover.join()
    result["load1"] = load1
    return result


def _medians(runs_by_name: dict[str, list[dict[str, Any]]]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for name, runs in runs_by_name.items():
        ordered = sorted(runs, key=lambda r: float(r["rps"]))
        out[name] = {"median": ordered[len(ordered) // 2], "runs": runs}
    return out


def _measure(kind: str, ctx: BenchContext) -> dict[str, Any]:
    with _server(kind, ctx) as (port, pid):
        return _medians(
            {name: [_run(port, name, pid) for _ in range(ctx.repeat)] for name in SCENARIOS}
        )


def _measure_beside_baseline(ctx: BenchContext) -> dict[str, Any]:
    """This poppy and the --baseline one, both served at once; in each round of each scenario
    one runs right after the other, the order swapping each round (baseline first in round 0)."""
    runs: dict[str, dict[str, list[dict[str, Any]]]] = {"poppy": {}, BASELINE_CLIENT: {}}
    with _server(BASELINE_CLIENT, ctx) as base, _server("poppy", ctx) as this:
        servers = {"poppy": this, BASELINE_CLIENT: base}
        for name in SCENARIOS:
            for rep in range(ctx.repeat):
                order = ("poppy", BASELINE_CLIENT) if rep % 2 else (BASELINE_CLIENT, "poppy")
                for side in order:
                    port, pid = servers[side]
                    run = _run(port, name, pid)
                    run["rep"] = rep
                    runs[side].setdefault(name, []).append(run)
    return {side: _medians(by_name) for side, by_name in runs.items()}


GOAL_RATIO = 2.0


def _median_cpu(raw: dict[str, Any], side: str, name: str) -> str:
    """The median over the runs of ``side`` of its process's CPU µs per request."""
    runs = raw.get(side, {}).get(name, {}).get("runs", [])
    spent = sorted(float(run["cpu_us"]) for run in runs if run.get("cpu_us"))
    return f"{spent[len(spent) // 2]:.1f}" if spent else "-"


@register("server", "REST requests/s and p50/p99 latency: poppy serve vs pypot's HTTP server")
def server_bench(ctx: BenchContext) -> BenchResult:
    """Measure both servers on every scenario."""
    raw: dict[str, Any] = {"clients": CLIENTS, "duration_s": DURATION_S, "goto_s": GOTO_S}
    tables: list[Table] = []
    label: str | None = None
    if ctx.baseline is not None:
        beside = _measure_beside_baseline(ctx)
        label = baseline_label(ctx.baseline)
        raw[BASELINE_CLIENT] = {"label": label, **beside[BASELINE_CLIENT]}

        def measure(kind: str, ctx: BenchContext) -> dict[str, Any]:
            return beside["poppy"] if kind == "poppy" else _measure(kind, ctx)

        sides, notes = measure_sides(ctx, measure, "server")
        for make in (baseline_rps_table, baseline_cpu_table):
            table, more = make(raw[BASELINE_CLIENT], sides["poppy"], label)
            tables.append(table)
            notes += more
        raw["calls"] = {"poppy": call_counts(), BASELINE_CLIENT: call_counts(ctx.baseline)}
    else:
        sides, notes = measure_sides(ctx, _measure, "server")
        raw["calls"] = {"poppy": call_counts()}
    failed = [side for side, counted in raw["calls"].items() if "error" in counted]
    if failed:
        notes += [raw["calls"][side]["error"] for side in failed]
    else:
        table, more = calls_table(raw["calls"], label)
        tables.append(table)
        notes += more
    raw.update(sides)
    rows = [[name, *median_cells(raw, name)] for name in SCENARIOS]
    headers = side_by_side.headers()
    # Goal (issue): at least 2x pypot's throughput with a lower p99.
    verdicts: list[bool] = []
    for row, name in zip(rows, SCENARIOS, strict=True):
        mine = raw.get("poppy", {}).get(name, {}).get("median")
        theirs = raw.get("pypot", {}).get(name, {}).get("median")
        if mine is None or theirs is None or not theirs["rps"]:
            row += ["-", "-"]
            continue
        ratio = mine["rps"] / theirs["rps"]
        met = ratio >= GOAL_RATIO and mine["p99_s"] < theirs["p99_s"]
        verdicts.append(met)
        row += [f"{ratio:.1f}x", "pass" if met else "**FAIL**"]
    headers += ["poppy / pypot", f">= {GOAL_RATIO:g}x, lower p99"]
    for row, name in zip(rows, SCENARIOS, strict=True):
        row += [_median_cpu(raw, side, name) for side in ("poppy", "pypot")]
    headers += ["poppy CPU µs/req", "pypot CPU µs/req"]
    notes.append(
        (
            f"Load: wrk, one thread, {CLIENTS} keep-alive connections"
            if shutil.which("wrk")
            else f"Load: {CLIENTS} Python client threads with keep-alive connections (install "
            "wrk for a client that does not cap the rate)"
        )
        + f", {math.ceil(DURATION_S) if shutil.which('wrk') else DURATION_S} s per run, "
        f"median of {ctx.repeat} runs (by req/s). The wait-goto scenario keeps a "
        f'`"wait": true` goto of {GOTO_S} s running on /motors/goto.json while measuring; '
        "pypot's tornado server answers nothing until each such goto ends. poppy rebuilds "
        "its `/robot.json` at most every 10 ms (the motors' values come from 50 Hz sync "
        "loops, so a 10 ms-old description says the same); pypot rebuilds it per request."
    )
    return BenchResult(
        name="server",
        title="REST server",
        intro=(
            "Requests per second and latency of pypot's REST routes on a virtual Ergo Jr, "
            "poppy (`poppy serve --http --sim`) against pypot 5 (`PoppyErgoJr(simulator="
            "'dummy', use_http=True)`), both on 127.0.0.1 in their own process."
        ),
        tables=[Table("REST server", headers, rows), *tables],
        notes=notes,
        passed=all(verdicts) if verdicts else None,
        raw=raw,
    )
