"""pypot's counterpart of bench/soak_client.py: a robot under faults until ``stop`` on stdin.

Run it with the peers venv: ``bench/.venv-peers/bin/python bench/peers/pypot_soak.py --config
poppy_ergo_jr.json --port my_dxl_controller=/tmp/soak/my_dxl_controller``.

``pypot.robot.from_config`` builds the robot (ports replaced, sensors dropped), every motor is
stiffened and a ``pypot.primitive.utils.Sinus`` moves them all (50 Hz). It prints ``ready T``
(system-wide monotonic clock), then counts each run of each controller's
``PosSpeedLoadDxlController`` update (its ``_update`` wrapped on the instance, as in
pypot_robot.py) per second, and records exceptions raised in it, until ``stop``. pypot has no
notion of a motor or a bus being offline: that part of the report stays empty. At the end it
says which of its threads are still alive, the RSS and thread counts, and how long
``robot.close()`` takes.
"""

from __future__ import annotations

import argparse
import contextlib
import sys
import threading
import time
from collections.abc import Callable
from typing import Any

from _common import emit, from_config, import_peer, parse_controller_port, peer_config
from _common import proc_status as common_proc_status

SINUS_AMPLITUDE_DEG = 10.0
SINUS_HZ = 0.5


def proc_status() -> dict[str, int]:
    """``_common.proc_status`` and Python's own count of threads."""
    return {**common_proc_status(), "python_threads": threading.active_count()}


class Counter:
    """Runs of one loop per second since ``t0``, and the errors they raised."""

    def __init__(self) -> None:
        self.t0: float | None = None
        self.bins: list[int] = []
        self.errors = 0
        self.last_error = ""

    def wrap(self, update: Callable[[], None]) -> Callable[[], None]:
        def counted() -> None:
            now = time.monotonic()
            if self.t0 is not None and now >= self.t0:
                second = int(now - self.t0)
                while len(self.bins) <= second:
                    self.bins.append(0)
                self.bins[second] += 1
            try:
                update()
            except Exception as exc:
                self.errors += 1
                self.last_error = f"{type(exc).__name__}: {exc}"[:200]
                raise

        return counted


def run(args: argparse.Namespace) -> dict[str, Any]:
    record: dict[str, Any] = {"peer": "pypot", "error": None}
    modules = import_peer(
        record, "pypot", "pypot.robot", "pypot.dynamixel.controller", "pypot.primitive.utils"
    )
    if modules is None:
        return record
    _, pypot_robot, dxl_controller, utils = modules
    config = peer_config(args.config, args.port)
    port_to_name = {port: name for name, port in args.port}
    start = time.perf_counter()
    robot = from_config(pypot_robot, config, record, sync=False)
    if robot is None:
        return record
    record["setup_s"] = time.perf_counter() - start
    closed = False
    try:
        counters: dict[str, Counter] = {}
        loops: dict[str, Any] = {}
        for meta in robot._controllers:
            name = port_to_name.get(meta.io.port, meta.io.port)
            loop = next(
                c
                for c in meta.controllers
                if isinstance(c, dxl_controller.PosSpeedLoadDxlController)
            )
            counters[name] = Counter()
            loop._update = counters[name].wrap(loop._update)
            loops[name] = loop
        robot.start_sync()
        for motor in robot.motors:
            motor.compliant = False
        sinus = utils.Sinus(robot, 50, robot.motors, amp=SINUS_AMPLITUDE_DEG, freq=SINUS_HZ)
        sinus.start()
        time.sleep(args.warmup_s)
        t0 = time.monotonic()
        for counter in counters.values():
            counter.t0 = t0
        record["start"] = proc_status()
        sys.stdout.write(f"ready {t0:.6f}\n")
        sys.stdout.flush()
        for line in sys.stdin:
            if line.strip() == "stop":
                break
        record["duration_s"] = time.monotonic() - t0
        record["end"] = proc_status()
        record["alive"] = {
            "sync": {name: bool(loop._thread.is_alive()) for name, loop in loops.items()},
            "primitive": bool(sinus.is_alive()),
        }
        record["reads_per_s"] = {name: c.bins for name, c in counters.items()}
        record["loop_errors"] = {name: c.errors for name, c in counters.items()}
        record["last_errors"] = {name: c.last_error for name, c in counters.items()}
        record["t0"] = t0
        began = time.perf_counter()
        try:
            sinus.stop()
            robot.close()
        except Exception as exc:
            record["close_error"] = f"{type(exc).__name__}: {exc}"[:200]
        closed = True
        record["close_s"] = time.perf_counter() - began
    finally:
        if not closed:
            with contextlib.suppress(Exception):
                robot.close()
    return record


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--config", required=True)
    parser.add_argument("--port", type=parse_controller_port, action="append", required=True)
    parser.add_argument("--warmup-s", type=float, default=2.0)
    try:
        record = run(parser.parse_args())
    except Exception as exc:
        record = {"peer": "pypot", "error": f"{type(exc).__name__}: {exc}"}
    emit(record)
    return 0 if record.get("error") is None else 1


if __name__ == "__main__":
    raise SystemExit(main())
