"""pypot's routes: same paths, methods, bodies, answer shapes and status codes."""

from __future__ import annotations

import httpx
import pytest

from poppy_core.robot.motor_link import link_of
from tests.helpers.robots import reached
from tests.helpers.server import Served
from tests.helpers.waiting import eventually

MOTORS = ["m1", "m2", "m3", "m4", "m5", "m6"]


def test_robot_json_lists_motors_with_registers_and_primitives(client: httpx.Client) -> None:
    answer = client.get("/robot.json")
    assert answer.status_code == 200
    body = answer.json()
    assert [m["name"] for m in body["motors"]] == MOTORS
    first = body["motors"][0]
    for register in ("present_position", "goal_position", "compliant", "led", "angle_limit"):
        assert register in first
    assert first["model"] == "XL-320"
    names = [p["primitive"] for p in body["primitives"]]
    assert "sinus" in names
    sinus = body["primitives"][names.index("sinus")]
    assert sinus["running"] is False
    assert {"property": "amplitude", "value": sinus["properties"][1]["value"]} in sinus[
        "properties"
    ]
    assert "start" in sinus["methods"]


def test_motor_lists_and_aliases(client: httpx.Client) -> None:
    assert client.get("/motors/list.json").json() == {"motors": MOTORS}
    assert client.get("/motors/aliases/list.json").json() == {"aliases": ["base", "tip"]}
    assert client.get("/motors/base/list.json").json() == {"base": ["m1", "m2", "m3"]}
    assert client.get("/motors/motors/list.json").json() == {"motors": MOTORS}
    missing = client.get("/motors/nope/list.json")
    assert missing.status_code == 404
    assert set(missing.json()) == {"error", "tip", "details"}


def test_registers_list_and_values(client: httpx.Client) -> None:
    registers = client.get("/motors/m1/registers/list.json").json()["registers"]
    assert "present_position" in registers and "goal_position" in registers
    value = client.get("/motors/m1/registers/present_position/value.json")
    assert value.status_code == 200
    assert isinstance(value.json()["present_position"], float)
    every = client.get("/motors/registers/present_temperature/list.json").json()
    assert set(every["present_temperature"]) == set(MOTORS)
    assert client.get("/motors/m9/registers/list.json").status_code == 404
    assert client.get("/motors/m1/registers/nope/value.json").status_code == 404
    assert client.get("/motors/registers/nope/list.json").status_code == 404


def test_register_write_answers_202_with_the_value(client: httpx.Client, served: Served) -> None:
    answer = client.post("/motors/m2/registers/compliant/value.json", content="false")
    assert answer.status_code == 202
    assert answer.json() == {"compliant": False}
    assert served.robot.m2.compliant is False
    answer = client.post("/motors/m2/registers/goal_position/value.json", content="12.5")
    assert answer.status_code == 202 and answer.json() == {"goal_position": 12.5}
    assert served.robot.m2.goal_position == pytest.approx(12.5, abs=0.5)
    client.post("/motors/m2/registers/compliant/value.json", content="true")


@pytest.mark.parametrize(
    ("register", "body", "value"),
    [
        ("compliant", "0", False),
        ("compliant", "1", True),
        ("compliant", '"False"', False),
        ("compliant", '"true"', True),
        ("goal_position", '"12"', 12),
        ("goal_position", '" -7.5 "', -7.5),
    ],
)
def test_register_values_as_pypot_clients_wrote_them(
    client: httpx.Client, served: Served, register: str, body: str, value: object
) -> None:
    motor = served.robot.m4
    motor.compliant = False
    answer = client.post(f"/motors/m4/registers/{register}/value.json", content=body)
    assert answer.status_code == 202, answer.text
    assert answer.json() == {register: value}
    if register == "compliant":
        assert motor.compliant is value
    else:
        assert motor.goal_position == pytest.approx(float(str(value)), abs=0.5)
    motor.compliant = True


@pytest.mark.parametrize(
    ("register", "body", "status"),
    [
        ("goal_position", "not json", 400),
        ("goal_position", "NaN", 400),
        ("goal_position", "Infinity", 400),
        ("goal_position", '"12x"', 400),
        ("goal_position", '"nan"', 400),
        ("goal_position", "1e309", 400),
        ("goal_position", "9" * 400, 400),
        ("goal_position", "true", 400),
        ("present_position", "3", 400),
        ("moving_speed", "-5", 400),
        ("torque_limit", "150", 400),
        ("compliant", "3", 400),
        ("compliant", '"yes"', 400),
        ("led", "[1, 2]", 400),
        ("led", '"purple-ish"', 400),
        ("pid", "[1, 2]", 400),
        ("angle_limit", "[10, -10]", 400),
        ("nope", "1", 404),
    ],
)
def test_bad_register_values_are_4xx_and_never_reach_the_motor(
    client: httpx.Client, served: Served, register: str, body: str, status: int
) -> None:
    motor = served.robot.m3
    before = (motor.goal_position, motor.moving_speed, motor.torque_limit, motor.led, motor.pid)
    answer = client.post(f"/motors/m3/registers/{register}/value.json", content=body)
    assert answer.status_code == status
    assert set(answer.json()) == {"error", "tip", "details"}
    assert (motor.goal_position, motor.moving_speed, motor.torque_limit, motor.led, motor.pid) == (
        before
    )
    link = link_of(motor)
    assert not link.has_pending() or link.take_pending(["goal_position"]) == {}


def test_motor_goto_and_motors_goto(client: httpx.Client, served: Served) -> None:
    served.robot.m1.compliant = False
    served.robot.m2.compliant = False
    answer = client.post("/motors/m1/goto.json", json={"position": 20, "duration": "0.3"})
    assert answer.status_code == 202
    assert answer.json() == {"motors": {"m1": 20.0}, "duration": 0.3, "waiting": False}
    answer = client.post(
        "/motors/goto.json",
        json={"motors": ["m1", "m2"], "positions": [-10, 15], "duration": 0.3, "wait": "true"},
    )
    assert answer.status_code == 202
    assert answer.json() == {"motors": {"m1": -10.0, "m2": 15.0}, "duration": 0.3, "waiting": True}
    assert eventually(lambda: reached(served.robot, {"m1": -10, "m2": 15}, 2.0))
    served.robot.compliant = True


@pytest.mark.parametrize(
    ("path", "body", "status"),
    [
        ("/motors/m1/goto.json", {"position": 10}, 400),
        ("/motors/m1/goto.json", {"position": "x", "duration": 1}, 400),
        ("/motors/m1/goto.json", {"position": 10, "duration": -1}, 400),
        ("/motors/m1/goto.json", {"position": 10, "duration": "nan"}, 400),
        ("/motors/m1/goto.json", {"position": 10, "duration": 86401}, 400),
        ("/motors/m9/goto.json", {"position": 10, "duration": 1}, 404),
        ("/motors/goto.json", {"motors": ["m1"], "positions": [1, 2], "duration": 1}, 400),
        ("/motors/goto.json", {"motors": ["m9"], "positions": [1], "duration": 1}, 404),
        ("/motors/goto.json", {"motors": "m1", "positions": [1], "duration": 1}, 400),
    ],
)
def test_bad_gotos(client: httpx.Client, path: str, body: object, status: int) -> None:
    answer = client.post(path, json=body)
    assert answer.status_code == status
    assert set(answer.json()) == {"error", "tip", "details"}


def test_no_store_and_options_like_pypot(client: httpx.Client) -> None:
    # pypot's open CORS needs --cors '*' (test_origins.py); scripts see no difference
    answer = client.get("/motors/list.json")
    assert answer.headers["cache-control"] == "no-store"
    assert "access-control-allow-origin" not in answer.headers
    options = client.options("/motors/m1/registers/goal_position/value.json")
    assert options.status_code == 204


def test_index_lists_the_routes(client: httpx.Client) -> None:
    answer = client.get("/routes")
    assert answer.status_code == 200
    assert "/robot.json" in answer.text and "/api/v1/gotos" in answer.text
