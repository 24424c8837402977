"""Run a poppy robot's sync loops on given ports and print loop start times as one JSON line.

Run as ``python -m bench.robot_client --config FILE --port CONTROLLER=PTY [...]``. It is the
poppy counterpart of bench/peers/pypot_robot.py: the robot is built from the same pypot JSON
config, its ports replaced by the emulator's ptys, and the start time of every read of the
present registers is recorded for ``--duration-s`` after ``--warmup-s``.

Timestamps are taken from outside the library: each bus's ``sync_read`` is wrapped (an
instance attribute of that ``DxlBus``, nothing in poppy_core is patched) and the calls that
read the present position are kept. With ``--rate-hz`` the robot's own loops are replaced by the
config's loops with the present loop at that rate, reading position, speed and load, through
``BusSync`` objects built from the robot's public buses and motors.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import replace
from typing import Any

from bench.peers._common import TimedCalls, parse_controller_port

# Timestamps are rounded to the microsecond in the JSON line.
_DIGITS = 6


class _Recorder(TimedCalls):
    """Start times of the reads at one address on one bus."""

    def __init__(self, address: int) -> None:
        super().__init__()
        self.address = address

    def wrap_read(self, read: Callable[..., Any]) -> Callable[..., Any]:
        """``read``, the starts of its reads at ``address`` noted."""

        def timed(address: int, length: int, ids: Sequence[int]) -> Any:
            if address == self.address:
                self.note()
            return read(address, length, ids)

        return timed


def run(args: argparse.Namespace) -> dict[str, Any]:
    """Build the robot, run its loops, and return the JSON-ready record."""
    record: dict[str, Any] = {"peer": "poppy", "error": None, "rate_hz": args.rate_hz}
    import poppy_core
    from poppy_core import from_config
    from poppy_core.errors import PoppyError
    from poppy_core.robot import BusSync, RobotConfig, load_config, loops_for
    from poppy_core.robot import registers as regs

    record["version"] = poppy_core.__version__
    config = load_config(args.config)
    data = config.to_dict()
    for name, port in args.port:
        data["controllers"][name]["port"] = port
    config = RobotConfig.from_dict(data, source=args.config)
    start = time.perf_counter()
    try:
        robot = from_config(config, fix_return_delay=True, start_sync=False, sensors=False)
    except PoppyError as exc:
        record["error"] = f"from_config failed: {type(exc).__name__}: {exc}"
        return record
    record["setup_s"] = time.perf_counter() - start
    try:
        recorders: dict[str, _Recorder] = {}
        syncs: list[BusSync] = []
        for name, bus in robot.buses.items():
            motors = [robot.motor(n) for n in config.motors_of_controller(name)]
            address = motors[0].model.register("present_position").address
            recorder = _Recorder(address)
            bus.sync_read = recorder.wrap_read(bus.sync_read)  # type: ignore[method-assign]
            recorders[name] = recorder
            if args.rate_hz is not None:
                loops = [
                    replace(spec, registers=regs.PRESENT, rate_hz=args.rate_hz)
                    if spec.name == "present"
                    else spec
                    for spec in loops_for(config.controllers[name].syncloop)
                ]
                syncs.append(BusSync(name, bus, motors, loops))
        if args.rate_hz is None:
            robot.start_sync()
        else:
            for sync in syncs:
                sync.start()
        cpu_start = time.process_time()
        begin = time.perf_counter() + args.warmup_s
        time.sleep(args.warmup_s + args.duration_s)
        end = time.perf_counter()
        record["loop_cpu_pct"] = (
            (time.process_time() - cpu_start) / (args.warmup_s + args.duration_s) * 100.0
        )
        stats = (
            robot.sync_stats() if args.rate_hz is None else {s.controller: s.stats() for s in syncs}
        )
        for sync in syncs:
            sync.stop()
        record["controllers"] = {
            name: {
                "port": robot.buses[name].port,
                "motors": len(config.motors_of_controller(name)),
                "sync_read_mode": robot.buses[name].sync_read_mode,
                "starts_s": [round(t - begin, _DIGITS) for t in rec.window(begin, end)],
                "window_s": end - begin,
                "library_stats": stats[name].as_dict() if name in stats else None,
            }
            for name, rec in recorders.items()
        }
    finally:
        robot.close()
    return record


def main(argv: list[str] | None = None) -> int:
    """Parse the command line, run the robot, print the JSON line; 0 on success, 1 on error."""
    parser = argparse.ArgumentParser(description="poppy robot sync loops (benchmark client)")
    parser.add_argument("--config", required=True, help="pypot JSON config")
    parser.add_argument("--port", type=parse_controller_port, action="append", required=True)
    parser.add_argument("--rate-hz", type=float, default=None, help="present loop rate")
    parser.add_argument("--duration-s", type=float, default=5.0)
    parser.add_argument("--warmup-s", type=float, default=1.0)
    record = run(parser.parse_args(argv))
    sys.stdout.write(json.dumps(record, sort_keys=True) + "\n")
    return 0 if record["error"] is None else 1


if __name__ == "__main__":
    sys.exit(main())
