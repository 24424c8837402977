"""``python -m bench zmq``: pypot's ZMQ request/reply protocol, poppy's server vs pypot's.

Both servers run in their own process on 127.0.0.1 over a virtual Ergo Jr (poppy: ``poppy serve
--zmq --sim``; pypot: ``ZMQRobotServer`` over ``PoppyErgoJr(simulator="dummy")``). One REQ
client in this process sends the same JSON requests back to back (REQ/REP is lockstep: one
request in flight per client) for ``DURATION_S``; requests/s and latency percentiles are taken
over the answered requests.
"""

from __future__ import annotations

import json
import subprocess
import time
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

from bench import side_by_side
from bench.procs import child, free_port, served_ergo
from bench.registry import BenchContext, BenchResult, Table, register
from bench.side_by_side import measure_sides, median, median_cells, percentile

DURATION_S = 1.5
START_TIMEOUT_S = 60.0
REPLY_TIMEOUT_MS = 5000

PYPOT_SERVER = """
import sys, threading, time
import pypot.creatures
from poppy_ergo_jr import PoppyErgoJr
from pypot.server import ZMQRobotServer
port = int(sys.argv[1])
robot = PoppyErgoJr(simulator="dummy")
server = ZMQRobotServer(robot, "127.0.0.1", port)
threading.Thread(target=server.run, daemon=True).start()
print("ready", flush=True)
try:
    while True:
        time.sleep(1)
except KeyboardInterrupt:
    robot.close()
"""

SCENARIOS: dict[str, dict[str, Any]] = {
    "get_register_value": {
        "robot": {"get_register_value": {"motor": "m1", "register": "present_position"}}
    },
    "set_register_value": {
        "robot": {"set_register_value": {"motor": "m1", "register": "goal_position", "value": "10"}}
    },
    "get_motors_list": {"robot": {"get_motors_list": {}}},
}


@contextmanager
def _server(kind: str, ctx: BenchContext) -> Iterator[int]:
    port = free_port()
    args = served_ergo(kind, ctx, PYPOT_SERVER, port, "--zmq", "--zmq-port", str(port))
    with child(args, stdout=subprocess.PIPE) as proc:
        assert proc.stdout is not None
        line = proc.stdout.readline()  # "zmq: tcp://..." / "ready": it serves
        if not line:
            err = proc.stderr.read() if proc.stderr else ""
            raise RuntimeError(f"the {kind} server exited: {err.strip()[-300:]}")
        yield port


def _load(port: int, request: dict[str, Any]) -> dict[str, Any]:
    import zmq

    context = zmq.Context()
    sock = context.socket(zmq.REQ)
    sock.setsockopt(zmq.RCVTIMEO, REPLY_TIMEOUT_MS)
    sock.setsockopt(zmq.LINGER, 0)
    sock.connect(f"tcp://127.0.0.1:{port}")
    payload = json.dumps(request).encode()
    latencies: list[float] = []
    error_replies = 0
    last_reply: Any = None
    try:
        end = time.monotonic() + DURATION_S
        t_start = time.monotonic()
        while time.monotonic() < end:
            t0 = time.perf_counter()
            sock.send(payload)
            raw = sock.recv()
            latencies.append(time.perf_counter() - t0)
            last_reply = json.loads(raw)
            if isinstance(last_reply, dict) and "error" in last_reply:
                error_replies += 1
        elapsed = time.monotonic() - t_start
    finally:
        sock.close()
        context.term()
    latencies.sort()

    return {
        "rps": len(latencies) / elapsed if elapsed else 0.0,
        "p50_s": percentile(latencies, 0.5),
        "p99_s": percentile(latencies, 0.99),
        "requests": len(latencies),
        "error_replies": error_replies,
        "last_reply": last_reply,
    }


def _measure(kind: str, ctx: BenchContext) -> dict[str, Any]:
    out: dict[str, Any] = {}
    with _server(kind, ctx) as port:
        _load(port, SCENARIOS["get_motors_list"])  # warm up
        for name, request in SCENARIOS.items():
            runs = [_load(port, request) for _ in range(ctx.repeat)]
            runs.sort(key=lambda r: r["rps"])
            out[name] = {"runs": runs, "median": runs[len(runs) // 2]}
    return out


@register("zmq", "ZMQ requests/s and p50/p99 latency: poppy serve --zmq vs pypot's ZMQRobotServer")
def zmq_bench(ctx: BenchContext) -> BenchResult:
    """Measure both servers on every scenario."""
    raw: dict[str, Any] = {"duration_s": DURATION_S}
    sides, notes = measure_sides(ctx, _measure, "server", (RuntimeError, OSError))
    raw.update(sides)
    rows = []
    for name in SCENARIOS:
        row = [name, *median_cells(raw, name, "error_replies")]
        mine, theirs = median(raw, "poppy", name), median(raw, "pypot", name)
        row.append(f"{mine['rps'] / theirs['rps']:.1f}x" if mine and theirs else "-")
        rows.append(row)
    headers = side_by_side.headers("request")
    headers.append("poppy / pypot")
    pypot_reply = raw.get("pypot", {}).get("get_register_value", {}).get("median", {})
    if pypot_reply.get("error_replies"):
        notes.append(
            "pypot 5.0.2's ZMQ server, on Python 3, answers every request with "
            f"`{json.dumps(pypot_reply.get('last_reply'))}`: it runs the request, then sends its "
            "answer as a str, which pyzmq refuses, and sends that error instead. Its figures "
            "are the round trip of a request that is executed but whose value never comes back."
        )
    notes.append(
        f"One REQ client, {DURATION_S} s per run, median of {ctx.repeat} runs (by req/s); "
        '`errors` counts `{"error": ...}` replies. The value is sent JSON-encoded in a '
        "string, as pypot's clients do."
    )
    return BenchResult(
        name="zmq",
        title="ZMQ server",
        intro=(
            "Requests per second and latency of pypot's ZMQ request/reply protocol on a "
            "virtual Ergo Jr, poppy (`poppy serve --zmq --sim`) against pypot 5 "
            "(`ZMQRobotServer` over `PoppyErgoJr(simulator='dummy')`), both on 127.0.0.1 in "
            "their own process."
        ),
        tables=[Table("ZMQ server", headers, rows)],
        notes=notes,
        passed=None,
        raw=raw,
    )
