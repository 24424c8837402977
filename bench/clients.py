"""Run a scan client (poppy, pypot, dynamixel-sdk) as a subprocess and collect its JSON line."""

from __future__ import annotations

import json
import resource
import subprocess
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from bench.registry import BENCH_DIR, REPO_ROOT

PEERS_VENV = BENCH_DIR / ".venv-peers"
PEERS_PYTHON = PEERS_VENV / "bin" / "python"
SETUP_SCRIPT = BENCH_DIR / "setup_peers.sh"
CLIENT_TIMEOUT_S = 300.0


@dataclass
class ClientRun:
    """One client process.

    Attributes:
        record: its JSON line (``error`` set when it printed none or failed).
        wall_s: wall time of the whole process, interpreter start-up included.
        cpu_s: CPU time (user + system) of the whole process.
    """

    record: dict[str, Any]
    wall_s: float
    cpu_s: float


def _children_cpu_s() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def run_client(
    args: list[str],
    *,
    json_lines: bool = True,
    cwd: Path = REPO_ROOT,
    env: dict[str, str] | None = None,
) -> ClientRun:
    """Run one client to completion and parse the JSON it prints.

    Clients run one at a time, so the growth of ``RUSAGE_CHILDREN`` is this client's CPU time.

    Args:
        args: the command line.
        json_lines: the output is one JSON line (a peer script); False for a JSON document
            (``poppy scan --json``), returned as ``{"output": ...}``.
        cwd: the folder it runs in (another checkout for a baseline client).
        env: its environment (None: this process's).

    Returns:
        The parsed record, wall time and CPU time.
    """
    cpu_before = _children_cpu_s()
    start = time.perf_counter()
    try:
        done = subprocess.run(
            args,
            capture_output=True,
            text=True,
            timeout=CLIENT_TIMEOUT_S,
            cwd=cwd,
            env=env,
            check=False,
        )
    except (OSError, subprocess.TimeoutExpired) as exc:
        wall = time.perf_counter() - start
        return ClientRun({"error": f"{type(exc).__name__}: {exc}"}, wall, 0.0)
    wall = time.perf_counter() - start
    cpu = _children_cpu_s() - cpu_before
    text = done.stdout.strip()
    try:
        if json_lines:
            record: dict[str, Any] = json.loads(text.splitlines()[-1])
        else:
            record = {"output": json.loads(text), "error": None}
    except (IndexError, ValueError):
        tail = (done.stderr.strip().splitlines() or ["no output"])[-1]
        record = {"error": f"exit {done.returncode}, no JSON: {tail}"}
    if done.returncode != 0 and not record.get("error"):
        tail = (done.stderr.strip().splitlines() or [f"exit {done.returncode}"])[-1]
        record["error"] = f"exit {done.returncode}: {tail}"
    return ClientRun(record, wall, cpu)


def _peers_import_ok() -> bool:
    if not PEERS_PYTHON.exists():
        return False
    done = subprocess.run(
        [str(PEERS_PYTHON), "-c", "import pypot.dynamixel, dynamixel_sdk"],
        capture_output=True,
        timeout=120,
        check=False,
    )
    return done.returncode == 0


def ensure_peers() -> tuple[Path | None, str]:
    """Make sure bench/.venv-peers can run the peer scripts, building it if needed.

    Returns:
        ``(python, "")`` when the peers are usable, else ``(None, reason)``.
    """
    if _peers_import_ok():
        return PEERS_PYTHON, ""
    try:
        done = subprocess.run(
            ["bash", str(SETUP_SCRIPT)],
            capture_output=True,
            text=True,
            timeout=1800,
            check=False,
        )
    except (OSError, subprocess.TimeoutExpired) as exc:
        return None, f"bench/setup_peers.sh could not run: {exc}"
    if _peers_import_ok():
        return PEERS_PYTHON, ""
    tail = (done.stderr.strip().splitlines() or ["no message"])[-1]
    return None, f"bench/setup_peers.sh failed (exit {done.returncode}): {tail}"
