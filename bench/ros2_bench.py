"""``python -m bench ros2``: one virtual Ergo Jr as a ROS 2 node (``poppy serve --ros2``).

A robot process (``bench.ros2_robot``) publishes ``joint_states`` at 50 Hz, then at 100 Hz; a
subscriber in this process, on rmw_zenoh's exact key over loopback, counts the messages over a
window and takes each one's age: its arrival against the source timestamp of rmw_zenoh's
attachment (one machine, one clock). The cost per robot is the robot process's CPU over the
window, against the same robot serving nothing.
"""

from __future__ import annotations

import os
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import Any

from bench.procs import free_port, interrupt
from bench.registry import POPPY_PYTHON, REPO_ROOT, BenchContext, BenchResult, Table, register
from bench.side_by_side import percentile

RATES = (50.0, 100.0)
WINDOW_S = 5.0
WARMUP_S = 2.0
TICK = os.sysconf("SC_CLK_TCK")
JOINT_STATES = (
    "0/joint_states/sensor_msgs::msg::dds_::JointState_/"
    "RIHS01_a13ee3a330e346c9d87b5aa18d24e11690752bd33a0350f11c5882bc9179260e"
)


def _start(*args: str) -> subprocess.Popen[str]:
    python = str(POPPY_PYTHON) if POPPY_PYTHON.exists() else sys.executable
    proc = subprocess.Popen(
        [python, "-m", "bench.ros2_robot", *args],
        stdout=subprocess.PIPE,
        text=True,
        cwd=REPO_ROOT,
        env={**os.environ, "PYTHONPATH": str(REPO_ROOT)},
    )
    assert proc.stdout is not None
    if proc.stdout.readline().strip() != "ready":
        interrupt(proc)
        raise RuntimeError("the robot process did not start")
    return proc


def _cpu_s(proc: subprocess.Popen[str]) -> float:
    fields = Path(f"/proc/{proc.pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / TICK  # utime, stime


def idle_cpu() -> float:
    """CPU (%) of the robot serving nothing."""
    proc = _start()
    try:
        time.sleep(WARMUP_S)
        before = _cpu_s(proc)
        time.sleep(WINDOW_S)
        return (_cpu_s(proc) - before) / WINDOW_S * 100.0
    finally:
        interrupt(proc)


def node_at(rate_hz: float) -> dict[str, Any]:
    """Delivered rate, age percentiles and the robot's CPU with ``joint_states`` at ``rate_hz``."""
    import zenoh

    from poppy_core.zenoh_wire import ZenohSettings, session_config

    endpoint = f"tcp/127.0.0.1:{free_port()}"
    proc = _start("--ros2", endpoint, "--rate", str(rate_hz))
    ages: list[float] = []
    counting = threading.Event()
    lock = threading.Lock()
    count = 0

    def on_sample(sample: Any) -> None:
        nonlocal count
        now = time.time_ns()
        if not counting.is_set() or sample.attachment is None:
            return
        stamp = int.from_bytes(sample.attachment.to_bytes()[8:16], "little", signed=True)
        with lock:
            count += 1
            ages.append((now - stamp) / 1e6)

    session = zenoh.open(session_config(ZenohSettings(connect=(endpoint,))))
    try:
        subscriber = session.declare_subscriber(JOINT_STATES, on_sample)
        time.sleep(WARMUP_S)
        before = _cpu_s(proc)
        counting.set()
        time.sleep(WINDOW_S)
        counting.clear()
        cpu = (_cpu_s(proc) - before) / WINDOW_S * 100.0
        subscriber.undeclare()  # type: ignore[no-untyped-call]
    finally:
        session.close()
        interrupt(proc)
    with lock:
        found = sorted(ages)
    return {
        "rate_hz": rate_hz,
        "received": count,
        "delivered_hz": count / WINDOW_S,
        "age_p50_ms": percentile(found, 0.5) or float("nan"),
        "age_p99_ms": percentile(found, 0.99) or float("nan"),
        "cpu_pct": cpu,
    }


def _fmt(value: float, digits: int = 1) -> str:
    return "-" if value != value else f"{value:.{digits}f}"


@register("ros2", "one Ergo Jr as a ROS 2 node: joint_states rate, age and cost at 50/100 Hz")
def ros2_bench(ctx: BenchContext) -> BenchResult:
    """One run per rate (the machine is shared)."""
    raw: dict[str, Any] = {"window_s": WINDOW_S, "load_before": os.getloadavg()[0]}
    raw["idle_cpu_pct"] = idle_cpu()
    raw["rates"] = [node_at(rate) for rate in RATES]
    raw["load_after"] = os.getloadavg()[0]
    idle = raw["idle_cpu_pct"]
    table = Table(
        "/joint_states on loopback, one subscriber",
        [
            "rate asked (Hz)",
            "delivered (Hz)",
            "age p50 / p99 (ms)",
            "robot CPU (%)",
            "cost of the node (% CPU)",
        ],
        [
            [
                f"{r['rate_hz']:g}",
                _fmt(r["delivered_hz"]),
                f"{_fmt(r['age_p50_ms'], 2)} / {_fmt(r['age_p99_ms'], 2)}",
                _fmt(r["cpu_pct"]),
                _fmt(r["cpu_pct"] - idle),
            ]
            for r in raw["rates"]
        ]
        + [["nothing served", "-", "-", _fmt(idle), "0"]],
    )
    notes = [
        f"One ideal-servo Ergo Jr in its own process; one run of {WINDOW_S:g} s after "
        f"{WARMUP_S:g} s of warm-up per rate. Each cycle publishes joint_states and tf (forward "
        "kinematics of the URDF's joints), diagnostics once a second; the cost column is the "
        "robot process's CPU minus the same robot serving nothing (its sync loop and emulator).",
        "The age is from the source timestamp of rmw_zenoh's attachment (taken just before the "
        "put) to the subscriber's callback: serialisation by rosbags is before it and not in it.",
        f"Load average (1 min) {raw['load_before']:.1f} before the run and "
        f"{raw['load_after']:.1f} after, on 2 cores shared with other sessions: the p99 measures "
        "the neighbours as much as poppy.",
    ]
    return BenchResult(
        name="ros2",
        title="ROS 2 node over rmw_zenoh",
        intro=(
            "A virtual Ergo Jr served with `poppy serve --ros2` publishes /joint_states on "
            "rmw_zenoh's key; a Zenoh subscriber on loopback (explicit endpoint, no scouting) "
            "receives it at 50 Hz and at 100 Hz."
        ),
        tables=[table],
        notes=notes,
        passed=None,
        raw=raw,
    )
