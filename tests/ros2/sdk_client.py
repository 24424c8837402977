"""A ROS 2 client written by others: zenoh-ros2-sdk (PyPI), a peer with rmw_zenoh's session
settings, run as its own process against a router: `python -m tests.ros2.sdk_client PORT NODE`.

It subscribes to /joint_states, /robot_description, /rosout and /diagnostics, prints ``ready``,
then waits for the robot, measures the joint_states rate over 2 s, calls ``NODE/set_compliant``
(stiff), sends a trajectory, then a refused one (an unknown joint), and prints one JSON line of
what it saw. Message definitions come from ``tests/ros2/interfaces`` (shipped, no download).
"""

from __future__ import annotations

import json
import os
import sys
import threading
import time
import traceback
from pathlib import Path
from typing import Any

INTERFACES = Path(__file__).with_name("interfaces")


def main(port: int, node: str) -> None:
    from zenoh_ros2_sdk import (
        ROS2Publisher,
        ROS2ServiceClient,
        ROS2Subscriber,
        ZenohSession,
        get_registry,
    )

    get_registry(str(INTERFACES))  # the first call fixes where definitions are read
    lock = threading.Lock()
    states: list[float] = []
    seen: dict[str, Any] = {"description": None, "rosout": [], "diagnostics": []}

    def on_state(msg: Any) -> None:
        with lock:
            states.append(time.monotonic())
            seen["names"] = list(msg.name)

    def on_description(msg: Any) -> None:
        seen["description"] = msg.data

    def on_rosout(msg: Any) -> None:
        seen["rosout"].append({"level": int(msg.level), "name": msg.name, "msg": msg.msg})

    def on_diagnostics(msg: Any) -> None:
        for status in msg.status:
            if status.name.endswith(": commands"):
                seen["diagnostics"].append({"level": int(status.level), "message": status.message})

    common = {"router_ip": "127.0.0.1", "router_port": port}
    subscribers = [
        ROS2Subscriber("/joint_states", "sensor_msgs/msg/JointState", on_state, **common),
        ROS2Subscriber("/robot_description", "std_msgs/msg/String", on_description, **common),
        ROS2Subscriber("/rosout", "rcl_interfaces/msg/Log", on_rosout, **common),
        ROS2Subscriber(
            "/diagnostics", "diagnostic_msgs/msg/DiagnosticArray", on_diagnostics, **common
        ),
    ]
    print("ready", flush=True)
    end = time.monotonic() + 120
    while not states and time.monotonic() < end:
        time.sleep(0.05)
    time.sleep(0.5)
    with lock:
        before = len(states)
    time.sleep(2.0)
    with lock:
        rate = (len(states) - before) / 2.0
    while seen["description"] is None and time.monotonic() < end:
        time.sleep(0.05)
    service = ROS2ServiceClient(
        f"/{node}/set_compliant", "std_srvs/srv/SetBool", timeout=30.0, **common
    )
    answer = service.call(data=False)
    trajectory = ROS2Publisher("/joint_trajectory", "trajectory_msgs/msg/JointTrajectory", **common)
    store = ZenohSession.get_instance().store
    point = store.types["trajectory_msgs/msg/JointTrajectoryPoint"]
    duration = store.types["builtin_interfaces/msg/Duration"]
    header = store.types["std_msgs/msg/Header"]
    stamp = store.types["builtin_interfaces/msg/Time"]
    time.sleep(1.0)  # the node's subscription learns of this publisher through the router

    def send(joint: str, radians: float) -> None:
        import numpy as np

        trajectory.publish(
            header=header(stamp=stamp(sec=0, nanosec=0), frame_id=""),
            joint_names=[joint],
            points=[
                point(
                    positions=np.array([radians]),
                    velocities=np.array([], dtype=np.float64),
                    accelerations=np.array([], dtype=np.float64),
                    effort=np.array([], dtype=np.float64),
                    time_from_start=duration(sec=1, nanosec=0),
                )
            ],
        )

    send("m1", 0.3)
    time.sleep(2.0)
    # /rosout is keep-last, so its publisher drops under congestion as rmw_zenoh's does (DROP,
    # not BLOCK): a busy machine may lose one refusal; each m9 sent is refused again
    resend, refused_by = 0.0, time.monotonic() + 60
    while time.monotonic() < refused_by and not (
        any("m9" in r["msg"] for r in seen["rosout"])
        and any(d["level"] == 1 for d in seen["diagnostics"])
    ):
        if time.monotonic() >= resend:
            send("m9", 0.1)
            resend = time.monotonic() + 3.0
        time.sleep(0.1)
    summary = {
        "rate": rate,
        "names": seen.get("names"),
        "description": (seen["description"] or "")[:200],
        "set_compliant": None if answer is None else [bool(answer.success), answer.message],
        "rosout": seen["rosout"],
        "diagnostics": seen["diagnostics"][-1:],
    }
    print(json.dumps(summary), flush=True)
    for subscriber in subscribers:
        subscriber.close()
    ZenohSession.get_instance().close()


if __name__ == "__main__":
    try:
        main(int(sys.argv[1]), sys.argv[2])
    except BaseException:
        traceback.print_exc()
        sys.stderr.flush()
        os._exit(1)  # the SDK's threads would keep a failed client alive
    sys.stdout.flush()
    os._exit(0)
