"""`poppy serve --ros2`: a served virtual Ergo Jr seen and driven as a ROS 2 node, over Zenoh,
by a client written from rmw_zenoh's design (loopback, explicit endpoints, scouting off)."""

from __future__ import annotations

import json
import logging
import math
import re
import socket
import threading
import time
from typing import Any

import numpy as np
import pytest

pytest.importorskip("zenoh")
pytest.importorskip("rosbags")

import itertools

import zenoh

from poppy_core import from_profile
from poppy_core.assembly import ServerSet, ServeSpec, serve
from poppy_core.robot import Robot
from poppy_core.ros2_wire import Ros2Settings
from poppy_core.zenoh_wire import ZenohSettings
from tests.helpers.waiting import eventually
from tests.ros2 import rmw_client as rmw
from tests.ros2.rmw_client import HASHES, Client, Collector

JOINT_STATE = "sensor_msgs/msg/JointState"
TRAJECTORY = "trajectory_msgs/msg/JointTrajectory"
SET_BOOL = "std_srvs/srv/SetBool"
TRIGGER = "std_srvs/srv/Trigger"


def free_endpoint() -> str:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return f"tcp/127.0.0.1:{sock.getsockname()[1]}"


def client_session(endpoint: str) -> zenoh.Session:
    config = zenoh.Config()
    config.insert_json5("mode", '"peer"')
    config.insert_json5("listen/endpoints", "[]")
    config.insert_json5("connect/endpoints", json.dumps([endpoint]))
    config.insert_json5("scouting/multicast/enabled", "false")
    config.insert_json5("scouting/gossip/enabled", "false")
    session = zenoh.open(config)
    assert eventually(lambda: bool(list(session.info.peers_zid())), 10.0)
    return session


class Node:
    """A virtual Ergo Jr served as ROS 2 node ``jr1`` and a client connected to it."""

    def __init__(self, domain: int = 0, namespace: str = "/") -> None:
        self.endpoint = free_endpoint()
        self.robot: Robot = from_profile("ergo-jr", sim=True)
        settings = Ros2Settings(
            domain=domain, namespace=namespace, zenoh=ZenohSettings(listen=(self.endpoint,))
        )
        self.servers: ServerSet = serve(self.robot, ServeSpec(ros2=settings, name="jr1"))
        self.session = client_session(self.endpoint)
        self.client = Client(self.session, domain)
        self.zid = str(self.servers.zenoh_session.info.zid())

    def close(self) -> None:
        self.client.close()
        self.session.close()
        self.servers.stop()
        self.robot.close()


def _header() -> Any:
    """A std_msgs/Header stamped 0, of no frame."""
    return rmw.msg(
        "std_msgs/msg/Header",
        stamp=rmw.msg("builtin_interfaces/msg/Time", sec=0, nanosec=0),
        frame_id="",
    )


def _joint_command(names: list[str], positions: Any) -> Any:
    """A sensor_msgs/JointState of ``names`` at ``positions`` (rad), stamped 0."""
    return rmw.msg(
        JOINT_STATE,
        header=_header(),
        name=names,
        position=positions,
        velocity=np.array([], dtype=float),
        effort=np.array([], dtype=float),
    )


def _stiff(node: Node) -> None:
    response, _ = node.client.call(
        "/jr1/set_compliant", SET_BOOL, rmw.msg(f"{SET_BOOL}_Request", data=False)
    )
    assert response.success
    assert eventually(lambda: not any(m.compliant for m in node.robot.motors))


def test_joint_states_decode_under_rmw_zenohs_key_with_the_attachment(node: Node) -> None:
    states = Collector(node.session, 0, "/joint_states", JOINT_STATE)
    try:
        assert eventually(lambda: len(states.snapshot()) >= 20, 20.0)
        samples = states.snapshot()
    finally:
        states.close()
    key, message, (_, stamp, gid) = samples[-1]
    # the published hash of sensor_msgs/msg/JointState (ros2 interface, rmw_zenoh keys)
    assert HASHES[JOINT_STATE].startswith("RIHS01_a13ee3a330e346c9")
    assert key == f"0/joint_states/sensor_msgs::msg::dds_::JointState_/{HASHES[JOINT_STATE]}"
    assert list(message.name) == [m.name for m in node.robot.motors]
    assert len(message.position) == len(message.velocity) == len(message.effort) == 6
    assert abs(stamp / 1e9 - time.time()) < 600  # a wall-clock time in ns, not a counter
    assert message.header.stamp.sec > 0
    assert len(gid) == 16
    # the cycles arrive in order from one writer: increasing sequence numbers, each cycle
    # numbered (/joint_states is keep-last, so its publisher drops under congestion as rmw_zenoh's
    # does: a machine at load 16 lost two of 20 in a run)
    sequences = [s[2][0] for s in samples]
    assert all(b > a for a, b in itertools.pairwise(sequences)), sequences
    assert len(sequences) >= 0.8 * (sequences[-1] - sequences[0] + 1), sequences
    assert {s[2][2] for s in samples} == {gid}


def test_positions_are_the_urdf_joints_angles_in_radians(node: Node) -> None:
    _stiff(node)
    node.robot.motor("m1").goal_position = 20.0  # direct: the joint turns with the motor
    node.robot.motor("m2").goal_position = 20.0  # indirect: against it
    states = Collector(node.session, 0, "/joint_states", JOINT_STATE)

    def near() -> bool:
        samples = states.snapshot()
        if not samples:
            return False
        position = samples[-1][1].position
        return (
            abs(position[0] - math.radians(20)) < 0.02
            and abs(position[1] + math.radians(20)) < 0.02
        )

    try:
        assert eventually(near, 20.0)
    finally:
        states.close()


def test_liveliness_tokens_of_node_publishers_subscriptions_and_services(node: Node) -> None:
    assert eventually(lambda: len(node.client.tokens()) >= 10, 10.0)
    tokens = node.client.tokens()
    head = f"@ros2_lv/0/{node.zid}/0"
    assert f"{head}/0/NN/%/%/jr1" in tokens

    def one(pattern: str) -> str:
        found = [t for t in tokens if re.fullmatch(pattern, t)]
        assert len(found) == 1, (pattern, tokens)
        return found[0]

    entity = r"/(\d+)/"
    one(
        re.escape(head)
        + entity
        + re.escape(
            f"MP/%/%/jr1/%joint_states/sensor_msgs::msg::dds_::JointState_/{HASHES[JOINT_STATE]}"
            "/::,10:,:,:,,"
        )
    )
    one(  # transient local (durability 1), depth 1, as robot_state_publisher declares it
        re.escape(head)
        + entity
        + re.escape(
            f"MP/%/%/jr1/%robot_description/std_msgs::msg::dds_::String_/"
            f"{HASHES['std_msgs/msg/String']}/:1:,1:,:,:,,"
        )
    )
    one(
        re.escape(head)
        + entity
        + re.escape(
            f"MS/%/%/jr1/%joint_trajectory/trajectory_msgs::msg::dds_::JointTrajectory_/"
            f"{HASHES[TRAJECTORY]}/::,10:,:,:,,"
        )
    )
    one(
        re.escape(head)
        + entity
        + re.escape(
            f"SS/%/%/jr1/%jr1%set_compliant/std_srvs::srv::dds_::SetBool_/{HASHES[SET_BOOL]}"
            "/::,10:,:,:,,"
        )
    )
    one(
        re.escape(head)
        + entity
        + re.escape(
            f"SS/%/%/jr1/%jr1%sinus%start/std_srvs::srv::dds_::Trigger_/{HASHES[TRIGGER]}/::,10:,:,:,,"
        )
    )
    ids = [t.split("/")[4] for t in tokens if t.startswith(head)]
    assert len(set(ids)) == len(ids)  # one entity id each


def test_domain_and_namespace_are_in_keys_and_tokens() -> None:
    served = Node(domain=7, namespace="/lab")
    try:
        states = Collector(served.session, 7, "/lab/joint_states", JOINT_STATE)
        try:
            assert eventually(lambda: bool(states.snapshot()), 20.0)
            assert states.snapshot()[0][0].startswith("7/lab/joint_states/")
        finally:
            states.close()
        assert eventually(lambda: bool(served.client.tokens()), 10.0)
        assert f"@ros2_lv/7/{served.zid}/0/0/NN/%/%lab/jr1" in served.client.tokens()
        response, _ = served.client.call(
            "/lab/jr1/set_compliant", SET_BOOL, rmw.msg(f"{SET_BOOL}_Request", data=False)
        )
        assert response.success
    finally:
        served.close()


def test_robot_description_reaches_a_late_joiner(node: Node) -> None:
    got = node.client.latched("/robot_description", "std_msgs/msg/String")
    assert eventually(lambda: bool(got), 10.0)
    assert "<robot" in got[0].data and 'name="m1"' in got[0].data


def test_set_bool_turns_compliance_off_and_on(node: Node) -> None:
    response, (sequence, _, gid) = node.client.call(
        "/jr1/set_compliant", SET_BOOL, rmw.msg(f"{SET_BOOL}_Request", data=False)
    )
    assert response.success
    assert sequence == node.client.sequence and gid == rmw.CLIENT_GID  # the request's id back
    assert not any(m.compliant for m in node.robot.motors)
    response, _ = node.client.call(
        "/jr1/set_compliant", SET_BOOL, rmw.msg(f"{SET_BOOL}_Request", data=True)
    )
    assert response.success
    assert all(m.compliant for m in node.robot.motors)


def test_trigger_starts_and_stops_a_primitive(node: Node) -> None:
    request = rmw.msg(f"{TRIGGER}_Request")
    response, _ = node.client.call("/jr1/sinus/start", TRIGGER, request)
    assert response.success
    assert "sinus" in node.servers.service.running_primitives()
    response, _ = node.client.call("/jr1/sinus/stop", TRIGGER, request)
    assert response.success
    assert "sinus" not in node.servers.service.running_primitives()


def _trajectory(names: list[str], points: list[tuple[float, list[float]]]) -> object:
    return rmw.msg(
        TRAJECTORY,
        header=_header(),
        joint_names=names,
        points=[
            rmw.msg(
                "trajectory_msgs/msg/JointTrajectoryPoint",
                positions=np.array(positions, dtype=float),
                velocities=np.array([], dtype=float),
                accelerations=np.array([], dtype=float),
                effort=np.array([], dtype=float),
                time_from_start=rmw.msg(
                    "builtin_interfaces/msg/Duration", sec=int(t), nanosec=int((t % 1) * 1e9)
                ),
            )
            for t, positions in points
        ],
    )


class Goals:
    """The goal of a motor, sampled in the background."""

    def __init__(self, node: Node, motor: str) -> None:
        self.values: list[float] = []
        self._motor = node.robot.motor(motor)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _run(self) -> None:
        while not self._stop.is_set():
            self.values.append(self._motor.goal_position)
            time.sleep(0.005)

    def close(self) -> None:
        self._stop.set()
        self._thread.join()
        self.values.append(self._motor.goal_position)


def test_a_trajectory_moves_a_joint_along_its_points(node: Node) -> None:
    _stiff(node)
    goals = Goals(node, "m1")
    try:
        node.client.publish(
            "/joint_trajectory",
            TRAJECTORY,
            _trajectory(["m1"], [(0.4, [math.radians(20)]), (0.8, [math.radians(-10)])]),
        )
        assert eventually(lambda: abs(node.robot.motor("m1").goal_position + 10) < 0.01, 20.0)
        assert eventually(lambda: not node.servers.ros2.commands.following, 10.0)
    finally:
        goals.close()
    values = goals.values
    top = values.index(max(values))
    # through the first point (each point is a goal once, at most one period late)...
    assert max(values) == pytest.approx(20.0, abs=1e-6)
    assert min(values[top:]) == pytest.approx(-10.0, abs=0.01)  # ...then to the second
    assert values[-1] == pytest.approx(-10.0, abs=0.01)
    assert eventually(lambda: abs(node.robot.motor("m1").present_position + 10) < 1.0, 20.0)


def test_the_next_trajectory_replaces_the_running_one(node: Node) -> None:
    _stiff(node)
    node.client.publish(
        "/joint_trajectory", TRAJECTORY, _trajectory(["m1"], [(30.0, [math.radians(40)])])
    )
    assert eventually(lambda: node.servers.ros2.commands.following, 10.0)
    node.client.publish(
        "/joint_trajectory", TRAJECTORY, _trajectory(["m1"], [(0.2, [math.radians(-15)])])
    )
    assert eventually(lambda: abs(node.robot.motor("m1").goal_position + 15) < 0.01, 20.0)
    assert eventually(lambda: not node.servers.ros2.commands.following, 10.0)


def _refusals(node: Node) -> int:
    return node.servers.ros2.commands.refused


def test_bad_commands_move_nothing(node: Node, caplog: pytest.LogCaptureFixture) -> None:
    _stiff(node)
    before = {m.name: m.goal_position for m in node.robot.motors}
    bad = [
        (["m1", "m9"], [0.1, 0.1]),  # an unknown joint
        (["m1", "m2"], [0.1, float("nan")]),  # NaN
        (["m1"], [1e12]),  # huge: refused as on every surface (not clamped)
        (["m1", "m2"], [0.1]),  # fewer positions than names
    ]
    caplog.set_level(logging.WARNING, logger="poppy_core.server.ros2.node")
    for count, (names, positions) in enumerate(bad, 1):
        node.client.publish(
            "/joint_command",
            JOINT_STATE,
            _joint_command(names, np.array(positions, dtype=float)),
        )
        assert eventually(lambda n=count: _refusals(node) == n, 10.0)  # type: ignore[misc]
    assert any("refused, nothing moved: no joint 'm9'" in r.getMessage() for r in caplog.records)
    assert {m.name: m.goal_position for m in node.robot.motors} == before
    seen = _refusals(node)
    node.client.publish(
        "/joint_trajectory", TRAJECTORY, _trajectory(["m1", "m7"], [(0.2, [0.1, 0.1])])
    )
    assert eventually(lambda: _refusals(node) == seen + 1, 10.0)
    assert not node.servers.ros2.commands.following
    assert {m.name: m.goal_position for m in node.robot.motors} == before


def test_a_goal_beyond_the_limits_is_clamped_to_them(node: Node) -> None:
    """The limit rule of every surface (ros2_control's saturation limiter does the same)."""
    _stiff(node)
    m1 = node.robot.motor("m1")
    low, high = m1.angle_limit
    node.client.publish("/joint_command", JOINT_STATE, _joint_command(["m1"], np.array([10.0])))
    assert eventually(lambda: abs(m1.goal_position - high) < 0.5, 10.0), m1.goal_position
    node.client.publish("/joint_trajectory", TRAJECTORY, _trajectory(["m1"], [(0.2, [-10.0])]))
    assert eventually(lambda: abs(m1.goal_position - low) < 0.5, 10.0), m1.goal_position
    assert eventually(lambda: not node.servers.ros2.commands.following, 10.0)
    assert node.servers.ros2.commands.refused == 0


def test_compliant_motors_are_not_moved_and_the_refusal_says_why(
    node: Node, caplog: pytest.LogCaptureFixture
) -> None:
    node.robot.compliant = True
    before = node.robot.motor("m1").goal_position
    with caplog.at_level(logging.WARNING, logger="poppy_core.server.ros2.node"):
        node.client.publish("/joint_trajectory", TRAJECTORY, _trajectory(["m1"], [(0.2, [0.3])]))
        assert eventually(lambda: _refusals(node) == 1, 10.0)
    assert node.robot.motor("m1").goal_position == before
    assert not node.servers.ros2.commands.following
    assert any("set_compliant" in r.getMessage() and "m1" in r.getMessage() for r in caplog.records)


def test_a_joint_command_sets_the_goals(node: Node) -> None:
    _stiff(node)
    node.client.publish(
        "/joint_command",
        JOINT_STATE,
        _joint_command(["m1", "m2"], np.array([math.radians(10), math.radians(10)])),
    )
    assert eventually(lambda: abs(node.robot.motor("m1").goal_position - 10) < 0.01, 10.0)
    assert node.robot.motor("m2").goal_position == pytest.approx(-10.0, abs=0.01)  # indirect


def test_stop_ends_the_trajectory_and_the_primitives(node: Node) -> None:
    _stiff(node)
    request = rmw.msg(f"{TRIGGER}_Request")
    node.client.publish(
        "/joint_trajectory", TRAJECTORY, _trajectory(["m2"], [(30.0, [math.radians(-30)])])
    )
    assert eventually(lambda: node.servers.ros2.commands.following, 10.0)
    # started from another surface (the node's own start ends its trajectory first; and a
    # trajectory sent while sinus drives m2 is refused: sinus owns it, tests/server/
    # test_motor_leases.py): a primitive's start is pypot's, never refused
    node.servers.service.control_primitive("sinus", "start")
    response, _ = node.client.call("/jr1/stop", TRIGGER, request)
    assert response.success and "sinus" in response.message
    assert not node.servers.ros2.commands.following
    assert node.servers.service.running_primitives() == []


def test_a_request_that_is_not_the_services_type_gets_an_error_reply(node: Node) -> None:
    replies = list(
        node.session.get(
            rmw.key(0, "/jr1/set_compliant", SET_BOOL),
            payload=b"\x07\x07",
            attachment=rmw.attachment(1),
            timeout=10.0,
        )
    )
    assert len(replies) == 1 and replies[0].err is not None
    assert b"bad request" in replies[0].err.payload.to_bytes()
    assert not any(m.compliant is False for m in node.robot.motors)  # nothing done
