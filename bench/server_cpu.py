"""The server benchmark's load-proof figures: CPU per request and Python calls per request.

On a shared machine a 2-second wrk run ranges over a factor of 10 from one run to the next; the
CPU a server spends per request it served moves far less (load steals time, not work). It is
read from ``/proc/PID/task/*/schedstat`` (nanoseconds on the CPU, per thread) before and after
each run: the whole process (its sync loops and emulator included), the same less the CPU the
process spent per second without requests just before the run (its background: a server that
serves fewer requests in a run would otherwise carry more of it per request), and its busiest
thread (the one serving HTTP). The calls per request are counted by ``bench/server_calls.py``
in each checkout's own interpreter, without a network: the same code answers the same way.
"""

from __future__ import annotations

import json
import os
import subprocess
import tempfile
import time
from pathlib import Path
from typing import Any

from bench.registry import BENCH_DIR, POPPY_PYTHON, REPO_ROOT

CALL_REQUESTS = 500
"""Requests per route counted (after 50 not counted)."""
CALLS_TIMEOUT_S = 300.0
IDLE_S = 0.5
"""How long a server's CPU is read with no request before each run (its background)."""


def thread_cpu_ns(pid: int) -> dict[str, int]:
    """Nanoseconds each thread of process ``pid`` has spent on a CPU so far."""
    spent: dict[str, int] = {}
    try:
        tasks = os.listdir(f"/proc/{pid}/task")
    except OSError:
        return spent
    for task in tasks:
        try:
            with open(f"/proc/{pid}/task/{task}/schedstat") as stat:
                spent[task] = int(stat.read().split()[0])
        except (OSError, ValueError, IndexError):
            continue  # a thread that ended meanwhile
    return spent


def cpu_per_request(before: dict[str, int], after: dict[str, int], requests: int) -> dict[str, Any]:
    """µs of CPU per request between two ``thread_cpu_ns`` readings: the whole process
    (``cpu_us``) and its busiest thread (``serving_cpu_us``); empty without requests."""
    if not requests or not after:
        return {}
    spent = [ns - before.get(task, 0) for task, ns in after.items()]
    return {
        "cpu_us": sum(spent) / requests / 1e3,
        "serving_cpu_us": max(spent) / requests / 1e3,
    }


def background_cpu(pid: int, seconds: float = IDLE_S) -> float:
    """Nanoseconds of CPU per second process ``pid`` spends with no request to answer (its
    sync loops, the emulator, a goto under way), over ``seconds``."""
    before = thread_cpu_ns(pid)
    t0 = time.monotonic()
    time.sleep(seconds)
    after = thread_cpu_ns(pid)
    spent = sum(ns - before.get(task, 0) for task, ns in after.items())
    return spent / (time.monotonic() - t0)


def net_of_background(spent: dict[str, Any], background_ns: float, requests: int) -> dict[str, Any]:
    """``net_cpu_us``: the process's CPU per request less what it spends without requests
    (``background_ns`` over the run), the share that grows when a server serves fewer."""
    if "cpu_us" not in spent or not requests:
        return {}
    return {"net_cpu_us": spent["cpu_us"] - background_ns / requests / 1e3}


def call_counts(folder: Path | None = None) -> dict[str, Any]:
    """Calls and in-process CPU per request of each route counted by ``server_calls.py``, for
    this checkout or the one in ``folder`` (its own ``poppy_core``, this interpreter)."""
    source = (BENCH_DIR / "server_calls.py").read_text()
    where = folder or REPO_ROOT
    env = dict(os.environ, PYTHONPATH=str(folder)) if folder is not None else None
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "calls.json"
        done = subprocess.run(
            [str(POPPY_PYTHON), "-c", source, str(out), str(CALL_REQUESTS)],
            cwd=where,
            env=env,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            text=True,
            timeout=CALLS_TIMEOUT_S,
            check=False,
        )
        if not out.exists():
            tail = done.stderr.strip().splitlines()[-1:] or ["no output"]
            return {"error": f"the count did not finish in {where}: {tail[0]}"}
        counted: dict[str, Any] = json.loads(out.read_text())
    return counted
