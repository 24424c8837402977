"""``python -m bench.fleet_robots``: N virtual Ergo Jrs served in one process, for ``bench fleet``.

Each robot: an ideal-servo Ergo Jr (its own 50 Hz sync loop and emulator), served on Zenoh as
``poppy/<name>`` on its own loopback port and/or on pypot's WebSocket at 50 Hz. Prints one line
per robot (``name zenoh-endpoint ws-port``), then ``ready``; stops on SIGINT. With ``--starts
FILE`` the time every ``Sinus`` primitive or move playback began is appended to FILE as ``pid
wall-clock-time`` (the fleet run/play spread is measured there, at the robots).
"""

from __future__ import annotations

import argparse
import contextlib
import os
import threading
import time
from pathlib import Path

from bench.procs import free_port
from poppy_core import from_profile
from poppy_core.assembly import Listen, ServeSpec, ZenohSettings, serve


def _log_starts(path: Path) -> None:
    """Append the wall-clock time every start really began, armed or not: a ``Sinus``
    primitive's ``setup`` and a move player's playback (``_run``), the first step of their
    thread once started."""
    from poppy_core.motion.builtins import Sinus
    from poppy_core.motion.player import MovePlayer

    lock = threading.Lock()

    def stamp() -> None:
        now = time.time()
        with lock, path.open("a", encoding="utf-8") as out:
            out.write(f"{os.getpid()} {now:.6f}\n")

    real_setup, real_run = Sinus.setup, MovePlayer._run

    def setup(self: Sinus) -> None:
        stamp()
        real_setup(self)

    def run(self: MovePlayer, stopping: threading.Event, at: float | None = None) -> None:
        stamp()
        real_run(self, stopping, at)

    Sinus.setup = setup  # type: ignore[method-assign]
    MovePlayer._run = run  # type: ignore[method-assign]


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--count", type=int, default=10)
    parser.add_argument("--first", type=int, default=0)
    parser.add_argument("--zenoh", action="store_true")
    parser.add_argument("--ws", action="store_true")
    parser.add_argument("--starts", type=Path)
    parser.add_argument("--router", help="connect only to this router (listen nowhere)")
    args = parser.parse_args()
    if args.starts is not None:
        _log_starts(args.starts)
    robots, sets = [], []
    try:
        for index in range(args.first, args.first + args.count):
            name = f"jr{index:02d}"
            robot = from_profile("ergo-jr", sim=True)
            robots.append(robot)
            endpoint = args.router or (f"tcp/127.0.0.1:{free_port()}" if args.zenoh else "")
            zenoh = None
            if args.zenoh:
                where = {"connect" if args.router else "listen": (endpoint,)}
                zenoh = ZenohSettings(**where)
            spec = ServeSpec(
                ws=Listen(port=0) if args.ws else None,
                ws_rate_hz=50.0,
                zenoh=zenoh,
                name=name,
            )
            servers = serve(robot, spec)
            sets.append(servers)
            ws_port = servers.ws.port if servers.ws is not None else 0
            print(name, endpoint or "-", ws_port, flush=True)
        print("ready", flush=True)
        with contextlib.suppress(KeyboardInterrupt):
            while True:
                time.sleep(1)
    finally:
        for servers in sets:
            servers.stop()
        for robot in robots:
            robot.close()


if __name__ == "__main__":
    main()
