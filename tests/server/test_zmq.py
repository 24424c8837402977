"""pypot's ZMQ request/reply protocol, spoken by a REQ socket as the documentation's client does."""

from __future__ import annotations

import json
from collections.abc import Iterator
from typing import Any

import pytest

from poppy_core.pypot import PoppyTorso
from poppy_core.robot import Robot
from poppy_core.server.zmqserver import ZmqRobotServer
from tests.creatures.helpers import wait_until
from tests.helpers.cli import command_env
from tests.helpers.processes import reap, start
from tests.helpers.waiting import scaled

zmq = pytest.importorskip("zmq")
TIMEOUT_MS = 10_000


@pytest.fixture(scope="module")
def robot() -> Iterator[Robot]:
    """A Torso as the documentation's ZMQ example drives it, serving ZMQ on a free port."""
    with PoppyTorso(simulator="dummy", use_zmq=True, zmq_port=0) as torso:
        yield torso


@pytest.fixture
def client(robot: Robot) -> Iterator[Any]:
    """A REQ socket connected to the robot's ZMQ server."""
    context = zmq.Context()
    socket = context.socket(zmq.REQ)
    socket.setsockopt(zmq.RCVTIMEO, TIMEOUT_MS)
    socket.setsockopt(zmq.LINGER, 0)
    socket.connect(f"tcp://127.0.0.1:{robot.zmq.port}")
    yield socket
    socket.close()
    context.term()


def ask(socket: Any, request: Any) -> Any:
    socket.send_json(request)
    return socket.recv_json()


def test_the_documentation_example_reads_and_writes_registers(robot: Robot, client: Any) -> None:
    # Poppy documentation, "ZMQ server": the example's requests, as sent.
    req = {"robot": {"get_register_value": {"motor": "head_z", "register": "present_pos"}}}
    client.send_json(req)
    answer = client.recv_json()
    assert isinstance(answer, float)
    robot.head_z.compliant = False
    req = {
        "robot": {"set_register_value": {"motor": "head_z", "register": "goal_pos", "value": 100}}
    }
    client.send_json(req)
    answer = client.recv_json()
    assert answer == {}
    limit = robot.head_z.upper_limit
    assert wait_until(lambda: abs(robot.head_z.present_position - min(100, limit)) < 2.0, 10.0)


def test_pypot_value_strings_and_lists(robot: Robot, client: Any) -> None:
    robot.head_y.compliant = False
    set_goal = {"motor": "head_y", "register": "goal_position", "value": json.dumps(-5.0)}
    assert ask(client, {"robot": {"set_motor_register_value": set_goal}}) == {}
    assert robot.head_y.goal_position == pytest.approx(-5.0, abs=0.2)
    motors = ask(client, {"robot": {"get_motors_list": {}}})
    assert motors == [m.name for m in robot.motors]
    assert ask(client, {"robot": {"get_motors_list": {"alias": "head"}}}) == ["head_z", "head_y"]
    registers = ask(client, {"robot": {"get_registers_list": {"motor": "head_z"}}})
    assert {"present_position", "lower_limit", "upper_limit"} <= set(registers)
    assert "head" in ask(client, {"robot": {"get_motors_alias": {}}})


def test_primitives_start_and_stop(robot: Robot, client: Any) -> None:
    assert "sinus" in ask(client, {"robot": {"get_primitives_list": {}}})
    assert ask(client, {"robot": {"start_primitive": {"primitive": "sinus"}}}) == {}
    assert "sinus" in ask(client, {"robot": {"get_running_primitives_list": {}}})
    assert ask(client, {"robot": {"stop_primitive": {"primitive": "sinus"}}}) == {}
    assert "sinus" not in ask(client, {"robot": {"get_running_primitives_list": {}}})
    props = ask(client, {"robot": {"get_primitive_properties_list": {"primitive": "sinus"}}})
    assert "amplitude" in props
    amplitude = {"primitive": "sinus", "property": "amplitude"}
    assert ask(client, {"robot": {"set_primitive_property": {**amplitude, "value": "12.5"}}}) == {}
    assert ask(client, {"robot": {"get_primitive_property": amplitude}}) == 12.5
    assert "start" in ask(client, {"robot": {"get_primitive_methods_list": {"primitive": "sinus"}}})


def test_goto_with_wait(robot: Robot, client: Any) -> None:
    robot.head_z.compliant = False
    goto = {"motor": "head_z", "position": 15, "duration": 0.3, "wait": True}
    assert ask(client, {"robot": {"set_goto_position_for_motor": goto}}) == {}
    assert robot.head_z.goal_position == pytest.approx(15.0, abs=0.5)  # the motion is over
    assert wait_until(lambda: abs(robot.head_z.present_position - 15.0) < 2.0, 10.0)


@pytest.mark.parametrize(
    ("request_", "says"),
    [
        ({"robot": {"no_such_method": {}}}, "no method"),
        ({"robot": {"get_register_value": {"motor": "nose", "register": "x"}}}, "no motor"),
        ({"robot": {"get_register_value": {"motor": "head_z"}}}, "bad arguments"),
        (
            {"robot": {"get_register_value": {"motor": "head_z", "register": "colour"}}},
            "no register",
        ),
        (
            {
                "robot": {
                    "set_register_value": {
                        "motor": "head_z",
                        "register": "goal_position",
                        "value": '"far"',
                    }
                }
            },
            "goal_position",
        ),
        ({"robot": "get_motors_list"}, "expected"),
        ([1, 2, 3], "expected"),
    ],
)
def test_bad_requests_get_an_error_and_the_server_carries_on(
    client: Any, request_: Any, says: str
) -> None:
    answer = ask(client, request_)
    assert says in answer["error"] and "\n" not in answer["error"]
    assert isinstance(ask(client, {"robot": {"get_motors_list": {}}}), list)


def test_garbage_bytes_get_an_error(client: Any) -> None:
    client.send(b"\xff\x00 not json")
    assert "not JSON" in client.recv_json()["error"]


def test_closing_the_robot_stops_the_server() -> None:
    robot = PoppyTorso(simulator="dummy", use_zmq=True, zmq_port=0)
    server = robot.zmq
    assert server.running
    robot.close()
    assert not server.running


def test_a_taken_port_is_one_clear_line(robot: Robot) -> None:
    from poppy_core.server.errors import ListenError

    with pytest.raises(ListenError, match=r"cannot listen on 127\.0\.0\.1"):
        ZmqRobotServer(robot, "127.0.0.1", robot.zmq.port)


def test_poppy_serve_zmq() -> None:
    import os
    import signal
    import sys

    env = dict(os.environ, **command_env())
    proc = start(
        [
            sys.executable,
            "-m",
            "poppy_cli",
            "serve",
            "--sim",
            "--profile",
            "ergo-jr",
            "--zmq",
            "--zmq-port",
            "0",
        ],
        env,
    )
    try:
        assert proc.stdout is not None
        line = proc.stdout.readline().strip()
        assert line.startswith("zmq: tcp://127.0.0.1:")
        context = zmq.Context()
        socket = context.socket(zmq.REQ)
        socket.setsockopt(zmq.RCVTIMEO, TIMEOUT_MS)
        socket.setsockopt(zmq.LINGER, 0)
        socket.connect(line.removeprefix("zmq: "))
        try:
            assert ask(socket, {"robot": {"get_motors_list": {}}})[0] == "m1"
        finally:
            socket.close()
            context.term()
        proc.send_signal(signal.SIGTERM)
        assert proc.wait(timeout=scaled(15)) == 0
    finally:
        reap(proc)


def test_the_documentation_server_in_a_thread(robot: Robot) -> None:
    # "ZMQ server" section: build the server, run it in a thread (address loopback, free port).
    import threading

    from poppy_core.server import ZMQRobotServer

    server = ZMQRobotServer(robot, "127.0.0.1", 0)
    runner = threading.Thread(target=lambda: server.run())
    runner.start()
    context = zmq.Context()
    socket = context.socket(zmq.REQ)
    socket.setsockopt(zmq.RCVTIMEO, TIMEOUT_MS)
    socket.setsockopt(zmq.LINGER, 0)
    socket.connect(server.url)
    try:
        assert "head_z" in ask(socket, {"robot": {"get_motors_list": {}}})
    finally:
        socket.close()
        context.term()
        server.stop()
        runner.join(10)
    assert not runner.is_alive()
