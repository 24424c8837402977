"""``python -m bench [NAME ...]``: run benchmarks, save raw JSON, rewrite docs/performance.md."""

from __future__ import annotations

import argparse
import logging
import sys
from pathlib import Path

from bench import (
    camera_bench,
    dataset_bench,
    emulator_bench,
    fleet_bench,
    ik_bench,
    move_bench,
    robot_bench,
    ros2_bench,
    scan_bench,
    server_bench,
    sim_bench,
    snap_bench,
    soak_bench,
    teleop_bench,
    timing_bench,
    web_bench,
    zmq_bench,
)
from bench.clients import ensure_peers
from bench.machine import machine_info
from bench.registry import BENCHMARKS, BenchContext
from bench.report import save_result, write_doc

logger = logging.getLogger("bench")

# Importing a benchmark module registers it; list them here so `--list` sees them all.
_MODULES = (
    scan_bench,
    robot_bench,
    move_bench,
    server_bench,
    sim_bench,
    ik_bench,
    camera_bench,
    teleop_bench,
    soak_bench,
    emulator_bench,
    snap_bench,
    web_bench,
    zmq_bench,
    fleet_bench,
    ros2_bench,
    timing_bench,
    dataset_bench,
)


def main(argv: list[str] | None = None) -> int:
    """Run the named benchmarks (all when none is named).

    Args:
        argv: command line; ``sys.argv[1:]`` when None.

    Returns:
        0 when every goal was met, 1 when one was missed, 2 on a usage error.
    """
    parser = argparse.ArgumentParser(prog="python -m bench", description=__doc__)
    parser.add_argument("names", nargs="*", help=f"benchmarks to run: {', '.join(BENCHMARKS)}")
    parser.add_argument("--repeat", type=int, default=3, help="runs per measurement (default 3)")
    parser.add_argument("--no-peers", action="store_true", help="measure poppy only")
    parser.add_argument("--list", action="store_true", help="list the benchmarks and exit")
    parser.add_argument(
        "--minutes",
        type=float,
        default=None,
        help="duration of the soak, per robot (default 10), and of the dataset episode (default 5)",
    )
    parser.add_argument(
        "--baseline",
        type=Path,
        default=None,
        help="another checkout of poppy (e.g. `git worktree add /tmp/old REV`) that `scan`, "
        "`emulator`, `server` and `camera` (its MJPEG viewers) measure beside this one, "
        "alternately",
    )
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="bench: %(message)s")
    if args.list:
        for bench in BENCHMARKS.values():
            note = " (long: runs only when named)" if bench.long else ""
            sys.stdout.write(f"{bench.name:10} {bench.summary}{note}\n")
        return 0
    unknown = [n for n in args.names if n not in BENCHMARKS]
    if unknown or args.repeat < 1:
        parser.error(f"unknown benchmark(s) {', '.join(unknown)}" if unknown else "--repeat < 1")
    if args.minutes is not None and not args.minutes > 0:
        parser.error("--minutes must be > 0")
    if args.baseline is not None and not (args.baseline / "poppy_core").is_dir():
        parser.error(f"--baseline {args.baseline}: no poppy_core folder there (a poppy checkout)")
    ctx = BenchContext(repeat=args.repeat, minutes=args.minutes, baseline=args.baseline)
    if args.no_peers:
        ctx.peers_note = "run with --no-peers"
    else:
        logger.info("checking the peers venv (bench/.venv-peers)")
        ctx.peers_python, ctx.peers_note = ensure_peers()
        if ctx.peers_python is None:
            logger.warning("peers unavailable, measuring poppy only: %s", ctx.peers_note)
    machine = machine_info(ctx.peers_python)
    all_passed = True
    for name in args.names or [n for n, b in BENCHMARKS.items() if not b.long]:
        logger.info("running %s", name)
        result = BENCHMARKS[name].func(ctx)
        path = save_result(result, machine)
        all_passed = all_passed and result.passed is not False
        logger.info(
            "%s: %s; raw results in %s",
            name,
            {True: "goals met", False: "GOALS MISSED", None: "done"}[result.passed],
            path,
        )
    doc = write_doc(BENCHMARKS)
    logger.info("wrote %s", doc)
    return 0 if all_passed else 1


if __name__ == "__main__":
    sys.exit(main())
