"""The robot processes of ``bench fleet`` and what runs beside them: 20 virtual Ergo Jrs in
``PROCESSES`` processes (``bench.fleet_robots``), their CPU, and subscribers that cannot keep up."""

from __future__ import annotations

import os
import subprocess
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from bench.procs import interrupt
from bench.registry import POPPY_PYTHON, REPO_ROOT

ROBOTS = 20
PROCESSES = 4
SLOW_S = 0.02
SLOW_SUBSCRIBERS = 20
SLOW_SUBSCRIBER = """
import os, sys, time
from poppy_core.remote.zenoh_fleet import Fleet
from poppy_core.zenoh_wire import ZenohSettings
count, delay, endpoints = int(sys.argv[1]), float(sys.argv[2]), tuple(sys.argv[3:])
fleets = [Fleet(ZenohSettings(connect=endpoints)) for _ in range(count)]
for fleet in fleets:
    fleet.on_state(lambda name, state: time.sleep(delay))
print("ready", flush=True)
try:
    while True:
        time.sleep(1)
except KeyboardInterrupt:
    os._exit(0)  # a session sleeping in its callback would not close in time: the sockets go
"""
"""COUNT Zenoh sessions (each its own client, as COUNT `fleet status` would be), each on every
robot's state, each sleeping DELAY s per message: subscribers that cannot keep up."""
TICK = os.sysconf("SC_CLK_TCK")


@contextmanager
def robot_processes(
    zenoh: bool,
    ws: bool,
    starts: Path | None = None,
    env: dict[str, str] | None = None,
    router: str | None = None,
) -> Iterator[tuple[list[Any], list[dict[str, Any]]]]:
    """Start the robot processes (``env``: more environment; ``router``: the robots connect
    only to it, their endpoint is its); yields them and one record per robot (name, endpoint,
    ws)."""
    procs, robots = [], []
    python = str(POPPY_PYTHON) if POPPY_PYTHON.exists() else sys.executable
    try:
        per = ROBOTS // PROCESSES
        for index in range(PROCESSES):
            args = [
                python,
                "-m",
                "bench.fleet_robots",
                "--count",
                str(per),
                "--first",
                str(index * per),
            ]
            args += ["--zenoh"] if zenoh else []
            args += ["--ws"] if ws else []
            args += ["--starts", str(starts)] if starts is not None else []
            args += ["--router", router] if router is not None else []
            full = {**os.environ, **(env or {}), "PYTHONPATH": str(REPO_ROOT)}
            procs.append(
                subprocess.Popen(args, cwd=REPO_ROOT, stdout=subprocess.PIPE, text=True, env=full)
            )
        for proc in procs:
            assert proc.stdout is not None
            for line in proc.stdout:
                if line.strip() == "ready":
                    break
                name, endpoint, ws_port = line.split()
                robots.append({"name": name, "endpoint": endpoint, "ws": int(ws_port)})
            else:
                raise RuntimeError("a robot process ended before it served")
        yield procs, robots
    finally:
        for proc in procs:
            interrupt(proc)
            if proc.stdout is not None:
                proc.stdout.close()


def cpu_s(procs: list[Any]) -> float:
    """The CPU time (user + system, s) ``procs`` used so far."""
    total = 0
    for proc in procs:
        fields = Path(f"/proc/{proc.pid}/stat").read_text().rsplit(")", 1)[1].split()
        total += int(fields[11]) + int(fields[12])  # utime, stime
    return total / TICK


def cpu_per_robot(procs: list[Any], window_s: float) -> float:
    before = cpu_s(procs)
    time.sleep(window_s)
    return (cpu_s(procs) - before) / window_s / ROBOTS * 100.0


@contextmanager
def slow_subscribers(count: int, endpoints: list[str]) -> Iterator[None]:
    """``count`` slow subscribers (``SLOW_SUBSCRIBER``) in a process of their own."""
    slow = subprocess.Popen(
        [sys.executable, "-c", SLOW_SUBSCRIBER, str(count), str(SLOW_S), *endpoints],
        cwd=REPO_ROOT,
        stdout=subprocess.PIPE,
        text=True,
        env={**os.environ, "PYTHONPATH": str(REPO_ROOT)},
    )
    try:
        assert slow.stdout is not None
        if slow.stdout.readline().strip() != "ready":
            raise RuntimeError("the slow subscribers did not start")
        yield
    finally:
        interrupt(slow)
        if slow.stdout is not None:
            slow.stdout.close()
