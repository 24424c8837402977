"""``python -m bench.ros2_robot``: one virtual Ergo Jr for ``bench ros2``, served as a ROS 2 node
(``--ros2``) or not served at all (the cost baseline). Prints ``ready``; stops on SIGINT."""

from __future__ import annotations

import argparse
import contextlib
import time

from poppy_core import from_profile
from poppy_core.assembly import ServeSpec, serve
from poppy_core.ros2_wire import Ros2Settings
from poppy_core.zenoh_wire import ZenohSettings


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--ros2", default="", help="the Zenoh endpoint to listen on")
    parser.add_argument("--rate", type=float, default=50.0)
    args = parser.parse_args()
    robot = from_profile("ergo-jr", sim=True)
    servers = None
    try:
        if args.ros2:
            settings = Ros2Settings(zenoh=ZenohSettings(listen=(args.ros2,)))
            spec = ServeSpec(ros2=settings, name="bench", state_rate_hz=args.rate)
            servers = serve(robot, spec)
        print("ready", flush=True)
        with contextlib.suppress(KeyboardInterrupt):
            while True:
                time.sleep(1)
    finally:
        if servers is not None:
            servers.stop()
        robot.close()


if __name__ == "__main__":
    main()
