"""Build a pypot robot from a JSON config on given ports, run its sync loops, print one JSON line.

Run it with the peers venv: ``bench/.venv-peers/bin/python bench/peers/pypot_robot.py
--config poppy_ergo_jr.json --port my_dxl_controller=/dev/pts/3``.

The config's controller ports are replaced by the given ones, its sensors are dropped (the Ergo
Jr's camera), and ``pypot.robot.from_config(config, sync=False)`` builds the robot. Before the
loops start, the ``_update`` of each controller's ``PosSpeedLoadDxlController`` (the 50 Hz loop
reading present position, speed and load) is wrapped on that instance to record when each
update starts; pypot's loop thread reads ``_update`` when it starts, so nothing in
site-packages is patched. ``--rate-hz`` sets that loop's ``period`` to ask for a higher rate.
"""

from __future__ import annotations

import argparse
import time
from typing import Any

from _common import TimedCalls, emit, from_config, import_peer, parse_controller_port, peer_config

# Timestamps are rounded to the microsecond in the JSON line.
_DIGITS = 6


def _loop_of(meta: Any, cls: type) -> Any:
    """The ``PosSpeedLoadDxlController`` among a ``MetaDxlController``'s loops."""
    return next(c for c in meta.controllers if isinstance(c, cls))


def run(args: argparse.Namespace) -> dict[str, Any]:
    """Build the pypot robot, run its loops, and return the JSON-ready record."""
    record: dict[str, Any] = {"peer": "pypot", "error": None, "rate_hz": args.rate_hz}
    modules = import_peer(record, "pypot", "pypot.robot", "pypot.dynamixel.controller")
    if modules is None:
        return record
    _, pypot_robot, dxl_controller = modules
    config = peer_config(args.config, args.port)
    port_to_name = {port: name for name, port in args.port}
    start = time.perf_counter()
    robot = from_config(pypot_robot, config, record, sync=False)
    if robot is None:
        return record
    record["setup_s"] = time.perf_counter() - start
    try:
        recorders: dict[str, TimedCalls] = {}
        loops: dict[str, Any] = {}
        for meta in robot._controllers:
            name = port_to_name.get(meta.io.port, meta.io.port)
            loop = _loop_of(meta, dxl_controller.PosSpeedLoadDxlController)
            recorder = TimedCalls()
            loop._update = recorder.wrap(loop._update)
            if args.rate_hz is not None:
                loop.period = 1.0 / args.rate_hz
            recorders[name] = recorder
            loops[name] = (meta, loop)
        robot.start_sync()
        cpu_start = time.process_time()
        begin = time.perf_counter() + args.warmup_s
        time.sleep(args.warmup_s + args.duration_s)
        end = time.perf_counter()
        record["loop_cpu_pct"] = (
            (time.process_time() - cpu_start) / (args.warmup_s + args.duration_s) * 100.0
        )
        record["controllers"] = {
            name: {
                "port": loops[name][0].io.port,
                "motors": len(loops[name][0].motors),
                "syncloop": type(loops[name][0]).__name__,
                "period_s": loops[name][1].period,
                "starts_s": [round(t - begin, _DIGITS) for t in rec.window(begin, end)],
                "window_s": end - begin,
            }
            for name, rec in recorders.items()
        }
    finally:
        robot.close()
    return record


def main(argv: list[str] | None = None) -> int:
    """Parse the command line, run the robot, print the JSON line.

    Args:
        argv: Arguments; ``sys.argv[1:]`` when None.

    Returns:
        0 on success, 1 on an error (given in the JSON line).
    """
    parser = argparse.ArgumentParser(description="pypot robot sync loops (benchmark peer)")
    parser.add_argument("--config", required=True, help="pypot JSON config")
    parser.add_argument("--port", type=parse_controller_port, action="append", required=True)
    parser.add_argument("--rate-hz", type=float, default=None, help="ask this loop rate")
    parser.add_argument("--duration-s", type=float, default=5.0)
    parser.add_argument("--warmup-s", type=float, default=1.0)
    record = run(parser.parse_args(argv))
    emit(record)
    return 0 if record["error"] is None else 1


if __name__ == "__main__":
    raise SystemExit(main())
