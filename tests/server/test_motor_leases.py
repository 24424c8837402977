"""One owner per motor goal across surfaces: a move, a teleoperation, a Zenoh goal stream and a
ROS 2 trajectory lease their motors; the v1 API's, Zenoh's and ROS 2's goals for a leased motor
are refused (409, one line naming the owner); pypot's routes keep writing (last write wins, as
pypot); a lost client, the end of a move and the robot-wide stop free the motors.

Before, every surface wrote ``goal_position`` and the last write won: a v1 goal POST while a
move played was accepted and overwritten at the next frame.
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import httpx
import pytest
from websockets.sync.client import connect

from poppy_core import from_profile
from poppy_core.assembly import Listen, ServerSet, ServeSpec, serve
from poppy_core.motion import Move, save_move
from tests.helpers.waiting import eventually, http_timeout

LONG = Move(10.0, ["m1", "m2"], [[0.0, 0.0]] * 600)  # a minute: still playing when stopped
ON_M2 = Move(10.0, ["m2"], [[0.0]] * 600)


@pytest.fixture
def served(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[ServerSet]:
    monkeypatch.setenv("POPPY_MOVES_DIR", str(tmp_path / "library"))
    save_move(LONG, "long")
    save_move(ON_M2, "on m2")
    with from_profile("ergo-jr", sim=True) as robot, serve(robot, ServeSpec(http=Listen())) as s:
        robot.compliant = False  # a compliant motor's goal is refused for that reason
        yield s


@pytest.fixture
def http(served: ServerSet) -> Iterator[httpx.Client]:
    assert served.http is not None
    with httpx.Client(base_url=served.http.url, timeout=http_timeout(10.0)) as client:
        yield client


def owners(http: httpx.Client) -> dict[str, str | None]:
    """Motor -> its owner as ``/api/v1/motors`` shows it."""
    answer = http.get("/api/v1/motors")
    assert answer.status_code == 200, answer.text
    return {m["name"]: m["owner"] for m in answer.json()}


def page_owners(http: httpx.Client) -> dict[str, str | None]:
    """Motor -> its owner as the page's motor table reads it (``/api/v1/web/motors``)."""
    motors = http.get("/api/v1/web/motors").json()["motors"]
    return {name: info["owner"] for name, info in motors.items()}


def put_goal(http: httpx.Client, motor: str, degrees: float) -> httpx.Response:
    return http.put(f"/api/v1/motors/{motor}/registers/goal_position", json={"value": degrees})


def ws_url(served: ServerSet) -> str:
    assert served.http is not None
    return served.http.url.replace("http://", "ws://") + "/api/v1/ws?rate_hz=5"


def ask(ws: Any, message: dict[str, Any]) -> dict[str, Any]:
    """Send a typed message, return the next answer (not a state frame or a state change)."""
    ws.send(json.dumps(message))
    while True:
        data = json.loads(ws.recv(timeout=10))
        if "error" in data or data.get("type") not in (None, "teleop.state"):
            return dict(data)


def test_a_move_playing_refuses_v1_goals_and_pypots_routes_still_write(
    http: httpx.Client, served: ServerSet
) -> None:
    assert http.post("/api/v1/moves/long/play", json={"speed": 1}).status_code == 202
    shown = owners(http)
    assert shown["m1"] == shown["m2"] == "move long from 127.0.0.1"
    assert shown["m3"] is None
    assert page_owners(http)["m1"] == "move long from 127.0.0.1"

    refused = put_goal(http, "m1", 10.0)
    assert refused.status_code == 409
    assert refused.json()["detail"] == (
        "m1 is driven by move long from 127.0.0.1: stop it first (POST /api/v1/moves/long/stop)"
    )
    many = http.patch("/api/v1/motors", json={"m2": {"goal_position": 5}, "m3": {"led": "red"}})
    assert many.status_code == 409 and "m2 is driven by move long" in many.json()["detail"]
    goto = http.post("/api/v1/gotos", json={"positions": {"m1": 5}, "duration_s": 0.5})
    assert goto.status_code == 409 and "m1 is driven by move long" in goto.text
    other_move = http.post("/api/v1/moves/on m2/play", json={"speed": 1})
    assert other_move.status_code == 409 and "m2 is driven by move long" in other_move.text
    assert put_goal(http, "m3", 10.0).status_code == 200  # a motor the move does not drive

    # pypot's register route writes as pypot does (its clients set goals while others run)
    pypot = http.post("/motors/m1/registers/goal_position/value.json", json=12.0)
    assert pypot.status_code == 202, pypot.text

    assert http.post("/api/v1/moves/long/stop").status_code == 200
    assert eventually(lambda: owners(http)["m1"] is None)
    assert put_goal(http, "m1", 10.0).status_code == 200


def test_teleop_holds_its_motors_until_its_connection_is_lost(
    http: httpx.Client, served: ServerSet
) -> None:
    with connect(ws_url(served)) as ws:
        started = ask(ws, {"type": "teleop.start", "motors": ["m2"]})
        assert started["type"] == "teleop.started"
        assert owners(http)["m2"] == "teleop from 127.0.0.1"
        refused = put_goal(http, "m2", 10.0)
        assert refused.status_code == 409
        assert refused.json()["detail"].startswith(
            "m2 is driven by teleop from 127.0.0.1: stop it first ("
        )
        play = http.post("/api/v1/moves/on m2/play", json={"speed": 1})
        assert play.status_code == 409 and "m2 is driven by teleop" in play.text
        # pypot's play route is never refused: the move owns the motors that were free
        pypot = http.post("/records/long/play.json", json={"speed": "1.0"})
        assert pypot.status_code == 202, pypot.text
        shown = owners(http)
        assert shown["m1"] == "move long from 127.0.0.1"
        assert shown["m2"] == "teleop from 127.0.0.1"
        assert http.post("/records/long/stop.json").status_code == 202
        # the client's own goals go on
        ws.send(json.dumps({"type": "teleop.goals", "positions": {"m2": 20.0}}))
    # the connection dropped without teleop.stop: its lease ends with it
    assert eventually(lambda: owners(http)["m2"] is None, timeout_s=10.0)
    assert put_goal(http, "m2", 10.0).status_code == 200


def test_the_robot_wide_stop_releases_every_lease(http: httpx.Client, served: ServerSet) -> None:
    with connect(ws_url(served)) as ws:
        assert ask(ws, {"type": "teleop.start", "motors": ["m4"]})["type"] == "teleop.started"
        assert http.post("/api/v1/moves/long/play", json={"speed": 1}).status_code == 202
        shown = owners(http)
        assert shown["m1"] == "move long from 127.0.0.1"
        assert shown["m4"] == "teleop from 127.0.0.1"
        stop = http.post("/api/v1/web/stop", json={"then": "hold"})
        assert stop.status_code == 200, stop.text
        assert owners(http) == dict.fromkeys(shown)
        for motor in ("m1", "m4"):
            assert put_goal(http, motor, 5.0).status_code == 200
        # the teleoperation was ended: its goals are refused until it starts again
        late = ask(ws, {"type": "teleop.goals", "positions": {"m4": 20.0}})
        assert "no teleoperation" in late["error"]


def test_a_running_primitive_owns_the_motors_it_drives(
    http: httpx.Client, served: ServerSet
) -> None:
    assert http.post("/api/v1/primitives/sinus/start").status_code == 200

    def driven() -> bool:
        return owners(http)["m1"] == "primitive sinus"

    assert eventually(driven)
    refused = put_goal(http, "m1", 10.0)
    assert refused.status_code == 409
    assert refused.json()["detail"] == (
        "m1 is driven by primitive sinus: stop it first (POST /api/v1/primitives/sinus/stop)"
    )
    assert http.post("/motors/m1/registers/goal_position/value.json", json=3.0).status_code == 202
    assert http.post("/api/v1/primitives/sinus/stop").status_code == 200
    assert eventually(lambda: owners(http)["m1"] is None)
    assert put_goal(http, "m1", 10.0).status_code == 200


# -- Zenoh's goal stream ------------------------------------------------------------------------


@pytest.fixture
def on_zenoh(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[tuple[ServerSet, Any]]:
    pytest.importorskip("zenoh")
    from poppy_core.zenoh_wire import ZenohSettings
    from tests.helpers.zenoh_served import free_endpoint
    from tests.ros2.test_ros2_node import client_session

    monkeypatch.setenv("POPPY_MOVES_DIR", str(tmp_path / "library"))
    endpoint = free_endpoint()
    spec = ServeSpec(http=Listen(), zenoh=ZenohSettings(listen=(endpoint,)), name="jr1")
    with from_profile("ergo-jr", sim=True) as robot, serve(robot, spec) as servers:
        robot.compliant = False
        session = client_session(endpoint)
        try:
            yield servers, session
        finally:
            session.close()


def _stream(servers: ServerSet, session: Any, goals: dict[str, float]) -> tuple[str, str]:
    """Put goals on ``poppy/jr1/goals`` until the robot handled one: ``("accepted", "")`` or
    the refusal's kind and line."""
    from poppy_core import zenoh_wire

    node: Any = servers.servers["zenoh"]
    payload = zenoh_wire.goals_message(goals, sender="tester")
    refused = node.refused_goals
    (motor, degrees), *_ = goals.items()
    target = servers.service.robot.motor(motor)

    def handled() -> bool:
        return node.refused_goals > refused or abs(target.goal_position - degrees) < 0.5

    for _ in range(3):  # a first message of a new publisher may find no route yet: again
        session.put("poppy/jr1/goals", payload)
        if eventually(handled, timeout_s=3.0):
            break
    if node.refused_goals > refused:
        assert node.last_refusal is not None
        return node.last_refusal
    return "accepted", ""


def test_teleop_refuses_a_zenoh_goal_stream_whose_own_lease_lapses_when_silent(
    on_zenoh: tuple[ServerSet, Any],
) -> None:
    servers, session = on_zenoh
    assert servers.http is not None
    with httpx.Client(base_url=servers.http.url, timeout=http_timeout(10.0)) as http:
        with connect(ws_url(servers)) as ws:
            assert ask(ws, {"type": "teleop.start", "motors": ["m2"]})["type"] == "teleop.started"
            kind, line = _stream(servers, session, {"m2": 30.0})
            assert kind == "conflict"
            assert line.startswith("m2 is driven by teleop from 127.0.0.1: stop it first")
            assert servers.service.robot.motor("m2").goal_position != pytest.approx(30.0, abs=0.5)
        assert eventually(lambda: owners(http)["m2"] is None, timeout_s=10.0)

        assert _stream(servers, session, {"m2": 30.0}) == ("accepted", "")
        assert owners(http)["m2"] == "goal stream from zenoh:tester"
        refused = put_goal(http, "m2", 0.0)
        assert refused.status_code == 409
        assert "m2 is driven by goal stream from zenoh:tester" in refused.json()["detail"]
        # the stream went silent: its lease lapses (GOAL_STREAM_LAPSE_S after its last goals)
        assert eventually(lambda: owners(http)["m2"] is None, timeout_s=10.0)
        assert put_goal(http, "m2", 0.0).status_code == 200


# -- ROS 2 -------------------------------------------------------------------------------------


@pytest.fixture
def on_ros2(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[tuple[ServerSet, Any]]:
    pytest.importorskip("zenoh")
    pytest.importorskip("rosbags")
    from poppy_core.ros2_wire import Ros2Settings
    from poppy_core.zenoh_wire import ZenohSettings
    from tests.helpers.zenoh_served import free_endpoint
    from tests.ros2.rmw_client import Client
    from tests.ros2.test_ros2_node import client_session

    monkeypatch.setenv("POPPY_MOVES_DIR", str(tmp_path / "library"))
    endpoint = free_endpoint()
    ros2 = Ros2Settings(zenoh=ZenohSettings(listen=(endpoint,)))
    spec = ServeSpec(http=Listen(), ros2=ros2, name="jr1")
    with from_profile("ergo-jr", sim=True) as robot, serve(robot, spec) as servers:
        robot.compliant = False
        session = client_session(endpoint)
        client = Client(session, 0)
        try:
            yield servers, client
        finally:
            client.close()
            session.close()


def test_a_ros2_trajectory_leases_its_joints_and_teleops_motors_refuse_ros2(
    on_ros2: tuple[ServerSet, Any],
) -> None:
    import math

    import numpy as np

    from tests.ros2.test_ros2_node import JOINT_STATE, TRAJECTORY, _joint_command, _trajectory

    servers, client = on_ros2
    node: Any = servers.servers["ros2"]
    refusals: list[Any] = []
    node.refusals.listen(refusals.append)
    assert servers.http is not None
    with (
        httpx.Client(base_url=servers.http.url, timeout=http_timeout(10.0)) as http,
        connect(ws_url(servers)) as ws,
    ):
        assert ask(ws, {"type": "teleop.start", "motors": ["m2"]})["type"] == "teleop.started"
        m2 = servers.service.robot.m2
        aimed = node.joints.to_motor("m2", 0.3)  # where the command would send it (degrees)
        command = _joint_command(["m2"], np.array([0.3]))

        def handled() -> bool:
            return bool(refusals) or abs(m2.goal_position - aimed) < 0.5

        for _ in range(3):  # a first message of a new publisher may find no route yet: again
            client.publish("/joint_command", JOINT_STATE, command)
            if eventually(handled, timeout_s=3.0):
                break
        assert refusals, f"the command was taken: m2 aims at {m2.goal_position}"
        assert refusals[-1].error == "conflict"
        assert refusals[-1].reason.startswith("m2 is driven by teleop from 127.0.0.1")

        long_one = _trajectory(["m1"], [(30.0, [math.radians(40)])])
        client.publish("/joint_trajectory", TRAJECTORY, long_one)
        assert eventually(lambda: owners(http)["m1"] == "trajectory from ROS 2", timeout_s=10.0)
        refused = put_goal(http, "m1", 0.0)
        assert refused.status_code == 409
        assert "m1 is driven by trajectory from ROS 2" in refused.json()["detail"]
        # ROS 2's own joint command passes its trajectory's lease and ends the trajectory
        client.publish("/joint_command", JOINT_STATE, _joint_command(["m1"], np.array([0.1])))
        assert eventually(lambda: owners(http)["m1"] is None, timeout_s=10.0)
        assert put_goal(http, "m1", 0.0).status_code == 200
