"""ROS 2 as ROS 2 deploys it: a router with rmw_zenoh's default settings, the robot served with
`--ros2` connected only to it, and a client written by others (zenoh-ros2-sdk, a peer with
rmw_zenoh's session settings) on the same router, in its own process."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from collections.abc import Iterator
from typing import Any

import pytest

pytest.importorskip("zenoh")
pytest.importorskip("rosbags")
pytest.importorskip("zenoh_ros2_sdk")

import zenoh

from poppy_core import from_profile
from poppy_core.assembly import ServeSpec, serve
from poppy_core.ros2_wire import Ros2Settings
from poppy_core.zenoh_wire import ZenohSettings
from tests.helpers.processes import read_until, reap
from tests.helpers.waiting import eventually, scaled
from tests.helpers.zenoh_router import Router
from tests.ros2.rmw_client import Client, Collector


@pytest.fixture
def router() -> Iterator[Router]:
    started = Router(rmw=True)
    try:
        yield started
    finally:
        started.kill()


def _client(router: Router, node: str) -> subprocess.Popen[str]:
    port = router.endpoint.rsplit(":", 1)[1]
    proc = subprocess.Popen(
        [sys.executable, "-m", "tests.ros2.sdk_client", port, node],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env={**os.environ, "ROS_DOMAIN_ID": "0"},
    )
    assert proc.stdout is not None
    ready = read_until(proc.stdout.fileno(), "ready", 120, proc)
    assert "ready" in ready, (ready, proc.poll())
    return proc


def test_an_independent_ros2_client_sees_and_drives_the_robot_through_the_router(
    router: Router,
) -> None:
    client = _client(router, "jr1")  # before the robot: the SDK's subscriptions are volatile
    robot = from_profile("ergo-jr", sim=True)
    spec = ServeSpec(ros2=Ros2Settings(zenoh=ZenohSettings(connect=(router.endpoint,))), name="jr1")
    servers = serve(robot, spec)
    try:
        assert robot.compliant
        out, err = client.communicate(timeout=scaled(240))
        assert client.returncode == 0, err[-3000:]
        summary: dict[str, Any] = json.loads(out.strip().splitlines()[-1])
        assert summary["names"] == ["m1", "m2", "m3", "m4", "m5", "m6"]
        assert summary["rate"] > 0, summary  # states flow (50 Hz measured: a bench figure)
        assert summary["description"].lstrip().startswith("<"), summary["description"]
        assert summary["set_compliant"][0] is True, summary
        assert not robot.m1.compliant
        assert eventually(lambda: abs(_m1_radians(servers) - 0.3) < 0.05, timeout_s=20)
        refusals = [r for r in summary["rosout"] if "m9" in r["msg"]]
        assert refusals and refusals[0]["level"] == 30 and refusals[0]["name"] == "jr1"
        assert "joint_trajectory refused, nothing moved" in refusals[0]["msg"]
        assert summary["diagnostics"][0]["level"] == 1
        assert "m9" in summary["diagnostics"][0]["message"]
    finally:
        reap(client)
        servers.stop()
        robot.close()


def _m1_radians(servers: Any) -> float:
    node = servers.ros2
    message = node.joints  # the joint of m1 in the URDF frame, as /joint_states publishes it
    from poppy_core.server.ros2 import messages

    state = messages.joint_state(node.robot, message)
    return float(dict(zip(state.name, state.position, strict=True))["m1"])


def rmw_peer(router: Router) -> zenoh.Session:
    """A session as rmw_zenoh's nodes open one (its DEFAULT_RMW_ZENOH_SESSION_CONFIG.json5's
    facts: a peer listening on loopback port 0, the router as its one endpoint, gossip on,
    multicast off, timestamps)."""
    config = zenoh.Config()
    for key, value in {
        "mode": "peer",
        "connect/endpoints": [router.endpoint],
        "listen/endpoints": ["tcp/127.0.0.1:0"],
        "scouting/multicast/enabled": False,
        "scouting/gossip/enabled": True,
        "scouting/gossip/multihop": False,
        "scouting/gossip/autoconnect": {"router": [], "peer": ["router", "peer"]},
        "timestamping/enabled": {"router": True, "peer": True, "client": False},
    }.items():
        config.insert_json5(key, json.dumps(value))
    return zenoh.open(config)


def test_an_rmw_zenoh_peer_gets_the_late_description_and_the_states_through_the_router(
    router: Router,
) -> None:
    """robot_description is transient local: a subscriber that comes after the robot still
    gets it (rmw_zenoh: an advanced subscriber asking the publishers' caches), through the
    router, from a session opened as rmw_zenoh's nodes open theirs."""
    robot = from_profile("ergo-jr", sim=True)
    spec = ServeSpec(ros2=Ros2Settings(zenoh=ZenohSettings(connect=(router.endpoint,))), name="jr2")
    servers = serve(robot, spec)
    session = rmw_peer(router)
    try:
        client = Client(session)
        description = client.latched("robot_description", "std_msgs/msg/String")
        assert eventually(lambda: bool(description), timeout_s=30)
        assert description[0].data.lstrip().startswith("<")
        states = Collector(session, 0, "joint_states", "sensor_msgs/msg/JointState")
        assert eventually(lambda: len(states.snapshot()) >= 20, timeout_s=30)
        assert any("/NN/" in token and "jr2" in token for token in client.tokens())
        states.close()
    finally:
        session.close()  # type: ignore[no-untyped-call]
        servers.stop()
        robot.close()
