"""Benchmark ``emulator``: how soon the emulator reads what a client wrote to its pty, and what
pypot's IO (which flushes the port before every packet) loses on ``poppy emulate`` and
``poppy sim --pty``.

Each session starts one emulator (``bench/emulator_stamp.py``: the command line as is, with
each chunk its reader takes off the pty stamped) and runs against it, one after the other:

* ``bench/emulator_ping.py``: PINGs every 5 ms; each one's delay from the client's write to
  the emulator's read of it (p50/p99);
* ``bench/peers/pypot_torque.py`` (peers venv): pypot 5.0.2's ``Dxl320IO`` as is, enabling
  then disabling the torque of the 6 XL-320 150 times (300 SYNC_WRITEs, each read back);
* the same with pypot's output flush skipped (the control: what the emulator itself loses).

Beside ``poppy emulate`` in each round, ``bench/emulator_minimal.py`` (one thread blocked in
``read()``, six XL-320 byte tables, nothing else) gets the same pypot runs: what any emulator
loses on this machine at that moment.

Each round also runs ``bench/emulator_flush.py`` with no emulator at all: a client writes to a
bare pty, flushes its output 15 µs later (the gap pypot leaves, which its runs report), with
nobody reading the master or with a process of its own blocked in ``read()`` on it, to tell
what the kernel discards from what a reader could save; and it times the kernel's worker (from
a write to the bytes being on the master's side).

Sessions run in rounds (``--repeat``, default 3), on ``poppy emulate --profile ergo-jr`` and
``poppy sim --profile ergo-jr --pty``. With ``--baseline DIR`` the older checkout's emulator
runs in the same round, right before or after this one's (the order swaps each round), so both
see the same load (as ``scan`` does).
"""

from __future__ import annotations

import json
import logging
import os
import select
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

from bench.clients import run_client
from bench.emulator_report import BASELINE, MINIMAL, THIS, build_result
from bench.procs import interrupt
from bench.registry import BENCH_DIR, REPO_ROOT, BenchContext, BenchResult, register
from bench.scan_baseline import baseline_label

logger = logging.getLogger(__name__)

MODES = {
    "poppy emulate --profile ergo-jr": ["emulate", "--profile", "ergo-jr"],
    "poppy sim --profile ergo-jr --pty": ["sim", "--profile", "ergo-jr", "--pty"],
}
IDS = 6
CYCLES = 150  # enable + disable each: 300 SYNC_WRITEs
PINGS = 300
START_TIMEOUT_S = 60.0
FLUSH_GAP_US = 15.0  # pypot's own, write() to its next flush (its gap_us p50: 12-18 µs here)
FLUSH_WRITES = 1000


def _session(tree: Path, args: list[str], peers: Path | None) -> dict[str, Any]:
    """One emulator from ``tree`` serving ``args``; the three clients against it."""
    env = {**os.environ, "PYTHONPATH": str(tree), "PYTHONUNBUFFERED": "1"}
    with tempfile.TemporaryDirectory(prefix="bench-emulator-") as folder:
        stamps_file = Path(folder) / "stamps.json"
        proc = subprocess.Popen(
            [sys.executable, str(BENCH_DIR / "emulator_stamp.py"), str(stamps_file), *args],
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
            stdin=subprocess.DEVNULL,
            text=True,
            cwd=tree,
            env=env,
        )
        out: dict[str, Any] = {"load1": round(os.getloadavg()[0], 2)}
        try:
            assert proc.stdout is not None
            ready, _, _ = select.select([proc.stdout], [], [], START_TIMEOUT_S)
            port = proc.stdout.readline().strip() if ready else ""
            if not port:
                return {**out, "error": "the emulator printed no port"}
            ping = run_client(
                [
                    sys.executable,
                    str(BENCH_DIR / "emulator_ping.py"),
                    "--port",
                    port,
                    "--count",
                    str(PINGS),
                ]
            ).record
            out.update(_pypot_runs(port, peers))
        finally:
            interrupt(proc)
            if proc.stdout is not None:
                proc.stdout.close()
        try:
            stamps = json.loads(stamps_file.read_text())
        except (OSError, ValueError):
            return {**out, "error": "the emulator wrote no stamps"}
    out["latency_us"] = _latencies(ping, stamps)
    return out


def _pypot_runs(port: str, peers: Path | None) -> dict[str, Any]:
    """pypot as is, then its control, on ``port``."""
    if peers is None:
        return {}
    torque = [
        str(peers),
        str(BENCH_DIR / "peers" / "pypot_torque.py"),
        "--port",
        port,
        "--cycles",
        str(CYCLES),
        "--ids",
        f"1-{IDS}",
    ]
    return {
        "pypot": run_client(torque).record,
        "control": run_client([*torque, "--keep-output"]).record,
    }


def _minimal_session(peers: Path | None) -> dict[str, Any]:
    """pypot against ``bench/emulator_minimal.py``."""
    proc = subprocess.Popen(
        [sys.executable, str(BENCH_DIR / "emulator_minimal.py")],
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        stdin=subprocess.DEVNULL,
        text=True,
        cwd=BENCH_DIR,
    )
    out: dict[str, Any] = {"load1": round(os.getloadavg()[0], 2)}
    try:
        assert proc.stdout is not None
        ready, _, _ = select.select([proc.stdout], [], [], START_TIMEOUT_S)
        port = proc.stdout.readline().strip() if ready else ""
        if not port:
            return {**out, "error": "the minimal responder printed no port"}
        return {**out, **_pypot_runs(port, peers)}
    finally:
        interrupt(proc)
        if proc.stdout is not None:
            proc.stdout.close()


def _latencies(ping: dict[str, Any], stamps: list[list[float]]) -> list[float]:
    """Each PING's delay from its write to the read of its last byte, in µs."""
    writes, size = ping.get("writes") or [], int(ping.get("size") or 0)
    delays: list[float] = []
    read_bytes, index = 0, 0
    for n, written_at in enumerate(writes):
        end = (n + 1) * size  # the PING's last byte, counted from the first
        while index < len(stamps) and read_bytes + stamps[index][1] < end:
            read_bytes += int(stamps[index][1])
            index += 1
        if index >= len(stamps):
            break
        delays.append(round((stamps[index][0] - written_at) * 1e6, 1))
    return delays


def _bare_pty(rep: int) -> list[dict[str, Any]]:
    """The flush experiment with no emulator: no reader, then a reader process (order swapped
    each round)."""
    readers = ["none", "process"] if rep % 2 == 0 else ["process", "none"]
    return [
        {
            **run_client(
                [
                    sys.executable,
                    str(BENCH_DIR / "emulator_flush.py"),
                    "--gap-us",
                    str(FLUSH_GAP_US),
                    "--count",
                    str(FLUSH_WRITES),
                    "--reader",
                    reader,
                ]
            ).record,
            "rep": rep,
            "load1": round(os.getloadavg()[0], 2),
        }
        for reader in readers
    ]


@register(
    "emulator",
    "pypot as is (flush before every packet) on poppy emulate and sim --pty; write-to-read delay",
)
def emulator(ctx: BenchContext) -> BenchResult:
    """Run ``ctx.repeat`` rounds of sessions on both commands (and the baseline's)."""
    trees = {THIS: REPO_ROOT}
    if ctx.baseline is not None:
        trees[BASELINE] = ctx.baseline.resolve()
    sessions: list[dict[str, Any]] = []
    bare: list[dict[str, Any]] = []
    for rep in range(ctx.repeat):
        bare += _bare_pty(rep)
    for label, args in MODES.items():
        for rep in range(ctx.repeat):
            order: list[tuple[str, Path | None]] = list(trees.items())
            if args[0] == "emulate":
                order.append((MINIMAL, None))
            if rep % 2:
                order.reverse()
            for who, tree in order:
                if tree is None:
                    session = _minimal_session(ctx.peers_python)
                else:
                    session = _session(tree, args, ctx.peers_python)
                session.update(mode=label, rep=rep, tree=who)
                logger.info(
                    "%s, round %d, %s: %s lost of %d",
                    label,
                    rep + 1,
                    who,
                    (session.get("pypot") or {}).get("lost", "-"),
                    IDS * 2 * CYCLES,
                )
                sessions.append(session)
    raw = {
        "sessions": sessions,
        "bare_pty": bare,
        "ids": IDS,
        "cycles": CYCLES,
        "pings": PINGS,
        "baseline": baseline_label(ctx.baseline) if ctx.baseline is not None else None,
        "peers_note": ctx.peers_note,
    }
    return build_result(raw)
