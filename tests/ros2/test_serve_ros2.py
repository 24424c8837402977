"""`poppy serve --ros2`: the command serves the node; bad ROS options are usage errors."""

from __future__ import annotations

import os
import subprocess

import pytest

pytest.importorskip("zenoh")
pytest.importorskip("rosbags")

from tests.helpers.cli import POPPY, command_env, run_poppy
from tests.helpers.processes import reap
from tests.helpers.waiting import eventually
from tests.ros2 import rmw_client as rmw
from tests.ros2.rmw_client import Client, Collector
from tests.ros2.test_ros2_node import SET_BOOL, client_session, free_endpoint


def test_poppy_serve_ros2_serves_the_node_in_its_namespace_and_domain() -> None:
    endpoint = free_endpoint()
    proc = subprocess.Popen(
        [
            *POPPY,
            "serve",
            "--ros2",
            "--name",
            "jr-7",
            "--ros-namespace",
            "lab",
            "--zenoh-listen",
            endpoint,
            "--profile",
            "ergo-jr",
            "--sim",
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=dict(os.environ, **command_env({"ROS_DOMAIN_ID": "3"})),
    )
    try:
        assert proc.stdout is not None
        line = proc.stdout.readline()
        assert line.startswith("ros2: node /lab/jr_7 on domain 3 (listening on tcp/127.0.0.1:")
        session = client_session(endpoint)
        try:
            states = Collector(session, 3, "/lab/joint_states", "sensor_msgs/msg/JointState")
            assert eventually(lambda: len(states.snapshot()) >= 3, 30.0)
            states.close()
            client = Client(session, 3)
            request = rmw.msg(f"{SET_BOOL}_Request", data=False)
            response, _ = client.call("/lab/jr_7/set_compliant", SET_BOOL, request)
            assert response.success and response.message == "stiff"
        finally:
            session.close()
    finally:
        reap(proc)


@pytest.mark.parametrize(
    ("args", "says"),
    [
        (["--http", "--ros-domain", "3"], "need --ros2"),
        (["--ros2", "--ros-namespace", "/9lab"], "not a ROS 2 namespace"),
        (["--ros2", "--ros-domain", "300"], "less than or equal to 232"),
        (["--ros2", "--zenoh-listen", "127.0.0.1:7447"], "not a Zenoh endpoint"),
    ],
)
def test_bad_ros2_options_are_usage_errors(args: list[str], says: str) -> None:
    result = run_poppy("serve", *args, "--profile", "ergo-jr", "--sim")
    assert result.code == 2
    assert says in result.stderr
    assert "Traceback" not in result.stderr
