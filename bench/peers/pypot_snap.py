"""pypot's Snap! server over an Ergo Jr on a given port (an emulator's pty), until interrupted.

Run it with the peers venv: ``bench/.venv-peers/bin/python bench/peers/pypot_snap.py
--port /dev/pts/3 --snap-port 6970``. It prints ``ready`` once the server answers.

The Ergo Jr is ``poppy_ergo_jr.PoppyErgoJr`` built from its own JSON config with the port
replaced and the sensors dropped (no camera here), with ``use_snap=True``: pypot's
``SnapRobotServer`` (bottle on tornado) in its background thread, as a classroom robot runs it.
ikpy 3.0.1 still uses ``numpy.float``, removed in numpy 1.24: the alias is restored at run
time so the creature's chain can be built. Nothing in site-packages is changed.
"""

from __future__ import annotations

import argparse
import json
import os
import socket
import tempfile
import time

import numpy

numpy.float = float  # type: ignore[attr-defined]  # ikpy 3.0.1 still uses the removed alias

import poppy_ergo_jr  # noqa: E402
from poppy_ergo_jr import PoppyErgoJr  # noqa: E402

START_TIMEOUT_S = 60.0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--port", required=True, help="the bus (a pty of poppy emulate)")
    parser.add_argument("--snap-port", type=int, required=True)
    parser.add_argument("--moves-dir", default=None, help="where pypot keeps .record files")
    args = parser.parse_args()
    folder = os.path.dirname(poppy_ergo_jr.__file__)
    with open(os.path.join(folder, "configuration", "poppy_ergo_jr.json")) as f:
        config = json.load(f)
    config.pop("sensors", None)
    config["controllers"]["my_dxl_controller"]["port"] = args.port
    with tempfile.NamedTemporaryFile("w", suffix=".json", delete=False) as f:
        json.dump(config, f)
    if args.moves_dir:
        os.chdir(args.moves_dir)  # pypot's Snap! moves live in the working directory
    robot = PoppyErgoJr(config=f.name, use_snap=True, snap_port=args.snap_port)
    deadline = time.monotonic() + START_TIMEOUT_S
    while time.monotonic() < deadline:
        try:
            with socket.create_connection(("127.0.0.1", args.snap_port), timeout=0.5):
                break
        except OSError:
            time.sleep(0.1)
    print("ready", flush=True)
    try:
        while True:
            time.sleep(1)
    except KeyboardInterrupt:
        robot.close()


if __name__ == "__main__":
    main()
