"""poppy's teleoperation client for the benchmark: ``python -m bench.teleop_client ...``.

Builds the leader (and the follower: another bus, a served robot, or the leader itself) from a
profile on the given ports, runs ``teleoperate`` until SIGINT/SIGTERM, then prints one JSON line:
``peer``, ``version``, ``error``, ``setup_s`` and ``report`` (``TeleopReport.as_dict()``). State
changes go to stderr as ``STATE <state> <reason>`` lines (the benchmark waits for
``STATE following``).
"""

from __future__ import annotations

import argparse
import json
import signal
import sys
import threading
import time
from importlib.metadata import version
from typing import Any


def _state(state: str, reason: str) -> None:
    sys.stderr.write(f"STATE {state} {reason}\n")
    sys.stderr.flush()


def run(args: argparse.Namespace) -> dict[str, Any]:
    """Build the robots, teleoperate until a signal, return the JSON-ready record."""
    from poppy_core import from_profile
    from poppy_core.motion.teleop.session import Teleoperation
    from poppy_core.remote import RemoteFollower

    record: dict[str, Any] = {"peer": "poppy", "version": version("poppy"), "error": None}
    stop = threading.Event()
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, lambda *_: stop.set())
    start = time.perf_counter()
    options: dict[str, Any] = {"sensors": False, "fix_return_delay": True}
    leader = from_profile(args.profile, args.leader_port, **options)
    follower: Any
    if args.follower_url:
        follower = RemoteFollower(args.follower_url, rate_hz=args.rate)
    elif args.follower_port:
        follower = from_profile(
            args.follower_profile or args.profile, args.follower_port, **options
        )
    else:
        follower = leader
    record["setup_s"] = time.perf_counter() - start
    try:
        teleop = Teleoperation(
            leader,
            follower,
            None if args.map is None else _map(args.map),
            rate_hz=args.rate,
            on_change=_state,
        ).start()
        while teleop.running and not stop.wait(0.05):
            pass
        teleop.stop()
        if teleop.error is not None:
            record["error"] = f"{type(teleop.error).__name__}: {teleop.error}"
        record["report"] = teleop.report().as_dict()
    finally:
        if follower is not leader:
            follower.close()
        leader.close()
    return record


def _map(text: str) -> Any:
    from poppy_core.motion.teleop.joint_map import JointMap

    return JointMap.parse(text)


def main(argv: list[str] | None = None) -> int:
    """Parse the command line, run, print the JSON line; 0 on success."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--profile", default="ergo-jr")
    parser.add_argument("--leader-port", required=True)
    parser.add_argument("--follower-port")
    parser.add_argument("--follower-profile")
    parser.add_argument("--follower-url")
    parser.add_argument("--map")
    parser.add_argument("--rate", type=float, default=100.0)
    args = parser.parse_args(argv)
    try:
        record = run(args)
    except Exception as exc:  # reported in the JSON line
        record = {"peer": "poppy", "error": f"{type(exc).__name__}: {exc}"}
    sys.stdout.write(json.dumps(record) + "\n")
    sys.stdout.flush()
    return 0 if record.get("error") is None else 1


if __name__ == "__main__":
    sys.exit(main())
