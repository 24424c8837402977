"""pypot's ``arms_copy_motion`` (poppy-torso's ``PuppetMaster``) on an emulated Torso bus.

Run it with the peers venv: ``bench/.venv-peers/bin/python bench/peers/pypot_arms_copy.py
--config poppy_torso.json --port upper_body_controller=/dev/pts/3``.

The config's ports are replaced by the given ones and its sensors dropped; ``pypot.robot.
from_config`` builds the robot (its sync loops at 50 Hz), and poppy-torso's ``PuppetMaster``
primitive (a 50 Hz ``LoopPrimitive``: the left arm compliant, each right-arm goal set to the
left arm's present position, negated for indirect motors) is attached as ``arms_copy_motion``
and started, as ``PoppyTorso.setup`` does. It runs until SIGINT/SIGTERM, then prints one JSON
line (``peer``, ``version``, ``error``, ``setup_s``). Nothing in site-packages is patched.
"""

from __future__ import annotations

import argparse
import signal
import sys
import threading
import time
from typing import Any

from _common import emit, from_config, import_peer, parse_controller_port, peer_config


def run(args: argparse.Namespace) -> dict[str, Any]:
    """Build the robot, copy the left arm to the right one until a signal, return the record."""
    record: dict[str, Any] = {"peer": "pypot", "error": None}
    stop = threading.Event()
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, lambda *_: stop.set())
    # pypot.creatures before poppy_torso (a circular import)
    modules = import_peer(
        record, "pypot", "pypot.robot", "pypot.creatures", "poppy_torso.primitives.interaction"
    )
    if modules is None:
        return record
    _, pypot_robot, _, interaction = modules
    config = peer_config(args.config, args.port)
    start = time.perf_counter()
    robot = from_config(pypot_robot, config, record)
    if robot is None:
        return record
    record["setup_s"] = time.perf_counter() - start
    try:
        primitive = interaction.PuppetMaster(robot, 50)
        robot.attach_primitive(primitive, "arms_copy_motion")
        primitive.start()
        time.sleep(0.5)
        sys.stderr.write("STATE following arms_copy_motion started\n")
        sys.stderr.flush()
        stop.wait()
        primitive.stop(wait=False)  # its teardown is a 2 s goto to 0: not measured
    finally:
        robot.close()
    return record


def main(argv: list[str] | None = None) -> int:
    """Parse the command line, run, print the JSON line; 0 on success."""
    parser = argparse.ArgumentParser(description="pypot arms_copy_motion (benchmark peer)")
    parser.add_argument("--config", required=True, help="pypot JSON config of a Torso")
    parser.add_argument("--port", type=parse_controller_port, action="append", required=True)
    record = run(parser.parse_args(argv))
    emit(record)
    return 0 if record["error"] is None else 1


if __name__ == "__main__":
    raise SystemExit(main())
