"""Scan benchmark: poppy, pypot and dynamixel-sdk scanning the same emulated buses.

Two emulators run in their own processes (``poppy emulate --wire-timing --latency-ms 1``): a
protocol 1 bus and a protocol 2 bus, both at 1 Mbps. Every client runs as a subprocess, one at
a time, and each measurement is repeated ``BenchContext.repeat`` times. With ``--baseline DIR``
the poppy of another checkout scans too, right before or after this one in every round (the
order swaps each round), so that both see the same load (see bench/scan_baseline.py).
"""

from __future__ import annotations

import logging
import os
from dataclasses import dataclass
from typing import Any

from bench.clients import ClientRun, run_client
from bench.emulator_proc import EmulatorError, EmulatorProcess
from bench.registry import (
    BENCH_DIR,
    POPPY_CLI,
    POPPY_PYTHON,
    BenchContext,
    BenchResult,
    register,
)
from bench.scan_baseline import BASELINE_CLIENT, baseline_label
from bench.scan_report import build_result

logger = logging.getLogger(__name__)

BAUD = 1_000_000
LATENCY_MS = 1.0
ALL_IDS = "0-253"


@dataclass(frozen=True)
class BusSpec:
    """One emulated bus: its motors and the IDs a correct scan must find."""

    protocol: int
    motors: str
    expected: tuple[int, ...]
    label: str


BUSES = (
    # The Poppy Torso/Humanoid arms use MX-28 (IDs 11-15 on the left arm) and the head AX-12A
    # (36, 37): a protocol 1 bus as Poppy wires it.
    BusSpec(
        1, "MX-28:11-15,AX-12A:36-37", (11, 12, 13, 14, 15, 36, 37), "Torso-like, MX-28 + AX-12A"
    ),
    # The Ergo Jr: six XL-320, IDs 1-6, protocol 2.
    BusSpec(2, "XL-320:1-6", (1, 2, 3, 4, 5, 6), "Ergo Jr, 6 × XL-320"),
)


@dataclass(frozen=True)
class Client:
    """A way of scanning one bus at 1 Mbps."""

    name: str
    peer: bool
    timed_by: str  # "scan": the client's own scan time; "wall": the whole process
    baseline: bool = False  # poppy from the --baseline checkout


def _clients(bus: BusSpec, peers: bool, baseline: bool) -> list[Client]:
    clients = [Client("poppy", False, "scan")]
    if baseline:
        clients.append(Client(BASELINE_CLIENT, False, "scan", baseline=True))
    if bus.protocol == 2:
        clients.append(Client("poppy (no broadcast)", False, "scan"))
    clients.append(Client("poppy scan CLI", False, "wall"))
    if peers:
        clients += [Client("pypot", True, "scan"), Client("dynamixel-sdk", True, "scan")]
    return clients


def _argv(client: Client, bus: BusSpec, port: str, ctx: BenchContext) -> list[str]:
    common = ["--port", port, "--baud", str(BAUD), "--protocol", str(bus.protocol)]
    if client.name.startswith("poppy scan CLI"):
        return [str(POPPY_CLI), "scan", *common, "--ids", ALL_IDS, "--json"]
    if client.name.startswith("poppy"):
        extra = ["--no-broadcast"] if "no broadcast" in client.name else []
        return [str(POPPY_PYTHON), "-m", "bench.poppy_client", *common, "--ids", ALL_IDS, *extra]
    script = "pypot_scan.py" if client.name == "pypot" else "sdk_scan.py"
    assert ctx.peers_python is not None
    return [str(ctx.peers_python), str(BENCH_DIR / "peers" / script), *common, "--ids", ALL_IDS]


def _found_ids(client: Client, run: ClientRun, bus: BusSpec) -> list[int]:
    if client.timed_by == "wall":
        motors = run.record.get("output") or []
        return sorted(
            int(m["id"]) for m in motors if m["protocol"] == bus.protocol and m["baud"] == BAUD
        )
    return sorted(int(i) for i in run.record.get("found") or [])


def _measure(
    client: Client, bus: BusSpec, emu: EmulatorProcess, ctx: BenchContext
) -> dict[str, Any]:
    where: dict[str, Any] = {}
    if client.baseline and ctx.baseline is not None:  # its own poppy_core and client script
        where = {"cwd": ctx.baseline, "env": {**os.environ, "PYTHONPATH": str(ctx.baseline)}}
    load1 = os.getloadavg()[0]
    emu_cpu = emu.cpu_s()
    run = run_client(
        _argv(client, bus, emu.port, ctx), json_lines=client.timed_by == "scan", **where
    )
    emu_cpu = emu.cpu_s() - emu_cpu
    found = _found_ids(client, run, bus) if not run.record.get("error") else []
    problem = run.record.get("error")
    if not problem and found != sorted(bus.expected):
        problem = f"wrong motors: found {found}, expected {list(bus.expected)}"
    scan_s = run.wall_s if client.timed_by == "wall" else run.record.get("elapsed_s")
    logger.info("%s on protocol %d: %s", client.name, bus.protocol, problem or f"{scan_s:.3f} s")
    return {
        "client": client.name,
        "protocol": bus.protocol,
        "ok": problem is None,
        "problem": problem,
        "scan_s": scan_s,
        "wall_s": run.wall_s,
        "cpu_s": run.cpu_s,
        "emulator_cpu_s": emu_cpu,
        "load1": load1,
        "found": found,
        "record": run.record,
    }


def _sweep(bus: BusSpec, emu: EmulatorProcess) -> dict[str, Any]:
    argv = [str(POPPY_PYTHON), "-m", "bench.poppy_client", "--port", emu.port, "--all-bauds"]
    argv += ["--protocol", "0", "--ids", ALL_IDS]
    run = run_client(argv)
    record = run.record
    expected = sorted([bus.protocol, BAUD, i] for i in bus.expected)
    problem = record.get("error")
    found = record.get("found_detail") or []
    if not problem and found != expected:
        problem = f"wrong motors: found {found}, expected {expected}"
    logger.info("sweep on the protocol %d bus: %s", bus.protocol, problem or record["elapsed_s"])
    return {
        "protocol": bus.protocol,
        "ok": problem is None,
        "problem": problem,
        "scan_s": record.get("elapsed_s"),
        "wall_s": run.wall_s,
        "cpu_s": run.cpu_s,
        "rates": record.get("rates") or [],
        "record": record,
    }


@register("scan", "full 0-253 scan at 1 Mbps vs pypot and dynamixel-sdk, plus the all-rates sweep")
def scan_benchmark(ctx: BenchContext) -> BenchResult:
    """Run the scan benchmark on both emulated buses (see the module docstring).

    Args:
        ctx: repeat count and the peers' interpreter.

    Returns:
        Tables, notes and raw runs for docs/performance.md and bench/results/scan.json.
    """
    runs: list[dict[str, Any]] = []
    sweeps: list[dict[str, Any]] = []
    emulators: list[dict[str, Any]] = []
    errors: list[str] = []
    for bus in BUSES:
        emu = EmulatorProcess(bus.motors, latency_ms=LATENCY_MS)
        try:
            emu.start()
        except EmulatorError as exc:
            errors.append(f"protocol {bus.protocol} bus: {exc}")
            continue
        emulators.append({"protocol": bus.protocol, "command": emu.command, "label": bus.label})
        try:
            clients = _clients(bus, ctx.peers_python is not None, ctx.baseline is not None)
            for rep in range(ctx.repeat):
                order = list(clients)
                if ctx.baseline is not None and rep % 2:
                    order[0], order[1] = order[1], order[0]  # neither always runs first
                for client in order:
                    runs.append({"rep": rep, **_measure(client, bus, emu, ctx)})
            for rep in range(ctx.repeat):
                sweeps.append({"rep": rep, **_sweep(bus, emu)})
        finally:
            emu.stop()
    return build_result(
        buses=[
            {
                "protocol": b.protocol,
                "motors": b.motors,
                "expected": list(b.expected),
                "label": b.label,
            }
            for b in BUSES
        ],
        emulators=emulators,
        runs=runs,
        sweeps=sweeps,
        errors=errors,
        peers_note=ctx.peers_note,
        repeat=ctx.repeat,
        baseline=baseline_label(ctx.baseline) if ctx.baseline is not None else None,
    )
