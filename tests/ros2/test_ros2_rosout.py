"""Refusals where ROS 2 users look: /rosout (rcl_interfaces/msg/Log) and /diagnostics."""

from __future__ import annotations

import numpy as np

from tests.helpers.waiting import eventually
from tests.ros2 import rmw_client as rmw
from tests.ros2.test_ros2_node import JOINT_STATE, Node, _joint_command

LOG = "rcl_interfaces/msg/Log"
DIAGNOSTICS = "diagnostic_msgs/msg/DiagnosticArray"


def _commands_status(node: Node) -> object:
    assert node.servers.ros2 is not None
    array = node.servers.ros2.diagnostics()
    return next(s for s in array.status if s.name == "jr1: commands")


def test_a_refused_command_is_a_warning_on_rosout_and_in_diagnostics(node: Node) -> None:
    from poppy_core.server.ros2.types import ros_type

    rmw.HASHES.setdefault(LOG, ros_type(LOG).hash)  # rosbags' hash of the Jazzy definition
    rosout = rmw.Collector(node.session, 0, "rosout", LOG)
    diagnostics = rmw.Collector(node.session, 0, "diagnostics", DIAGNOSTICS)
    try:
        status = _commands_status(node)
        assert status.level == 0 and status.message == "ok"  # type: ignore[attr-defined]
        for _ in range(5):  # a burst: published once (once a second at most), counted five times
            node.client.publish(
                "/joint_command", JOINT_STATE, _joint_command(["m9"], np.array([0.1]))
            )
        assert node.servers.ros2 is not None
        ros2 = node.servers.ros2
        assert eventually(lambda: ros2.commands.refused == 5, 10.0)
        assert eventually(lambda: bool(rosout.snapshot()), 10.0)
        logs = [message for _, message, _ in rosout.snapshot()]
        assert len(logs) == 1
        assert logs[0].level == 30 and logs[0].name == "jr1"
        assert logs[0].msg.startswith("/joint_command refused, nothing moved: no joint 'm9'")
        status = _commands_status(node)
        assert status.level == 1  # type: ignore[attr-defined]
        assert "no joint 'm9'" in status.message  # type: ignore[attr-defined]
        values = {kv.key: kv.value for kv in status.values}  # type: ignore[attr-defined]
        assert values["refused"] == "5"

        def published_warning() -> bool:
            return any(
                s.name == "jr1: commands" and s.level == 1
                for _, array, _ in diagnostics.snapshot()
                for s in array.status
            )

        assert eventually(published_warning, 10.0)
    finally:
        rosout.close()
        diagnostics.close()
