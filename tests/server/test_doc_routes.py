"""The documentation's REST examples answer: old route spellings, /ip.json, pypot's keys."""

from __future__ import annotations

import json
import urllib.request
from collections.abc import Iterator

import httpx
import pytest

from poppy_core.pypot import PoppyErgoJr
from poppy_core.server.legacy_paths import current_path
from tests.server.conftest import Served

MOTORS = ["m1", "m2", "m3", "m4", "m5", "m6"]


@pytest.fixture(scope="module")
def served(moves_folder: str) -> Iterator[Served]:
    """An Ergo Jr as the documentation serves one: ``PoppyErgoJr(use_http=True)``."""
    robot = PoppyErgoJr(simulator="dummy", use_http=True, http_port=0)
    try:
        yield Served(robot.http.url, robot, None)
    finally:
        robot.close()


def test_the_documentation_table(client: httpx.Client, served: Served) -> None:
    # "A few examples are given in the table below" (REST API section).
    assert client.get("/motor/list.json").json() == {"motors": MOTORS}
    position = client.get("/motor/m3/register/present_position")
    assert position.status_code == 200
    assert position.json()["present_position"] == pytest.approx(
        served.robot.m3.present_position, abs=1.0
    )
    started = client.get("/primitive/dance/start.json")
    assert started.status_code == 202
    try:
        assert served.robot.dance.running
    finally:
        client.get("/primitive/dance/stop.json")
    assert not served.robot.dance.running


def test_the_documentation_client_code(served: Served) -> None:
    # The urllib example of "HTTP method" (Python 3's urllib for urllib2), as written.
    allmotors = urllib.request.urlopen(f"{served.url}/motor/list.json").read()
    allmotors_dict = json.loads(allmotors)
    assert allmotors_dict["motors"] == MOTORS
    served.robot.m1.compliant = False
    url = f"{served.url}/motor/m1/register/goal_position/value.json"
    values = json.dumps(-20).encode()
    req = urllib.request.Request(url, values)
    req.add_header("Content-Type", "application/json")
    with urllib.request.urlopen(req) as response:
        assert response.status == 202
    assert served.robot.m1.goal_position == pytest.approx(-20.0, abs=0.5)


def test_ip_json_as_pypot(client: httpx.Client) -> None:
    answer = client.get("/ip.json")
    if answer.status_code == 200:
        assert set(answer.json()) == {"ip"} and answer.json()["ip"].count(".") == 3
    else:  # a machine without a network route: pypot's 404 with an error and a tip
        assert answer.status_code == 404 and {"error", "tip"} <= set(answer.json())


def test_robot_json_keeps_pypot_keys_and_types(client: httpx.Client) -> None:
    motor = client.get("/robot.json").json()["motors"][0]
    assert isinstance(motor["id"], int) and motor["model"] == "XL-320"
    assert motor["lower_limit"] == motor["angle_limit"][0]
    assert motor["upper_limit"] == motor["angle_limit"][1]
    assert motor["control_mode"] == "joint"
    assert "present_position" in motor["registers"] and isinstance(motor["safe_compliant"], bool)


@pytest.mark.parametrize(
    ("old", "new"),
    [
        ("/motor/alias/list.json", "/motors/aliases/list.json"),
        ("/motor/base/list.json", "/motors/base/list.json"),
        ("/motor/m1/register/list.json", "/motors/m1/registers/list.json"),
        ("/motor/m1/register/led/value.json", "/motors/m1/registers/led/value.json"),
        ("/motor/m1/goto.json", "/motors/m1/goto.json"),
        ("/primitive/list.json", "/primitives/list.json"),
        ("/primitive/running/list.json", "/primitives/running/list.json"),
        ("/primitive/sinus/property/list.json", "/primitives/sinus/properties/list.json"),
        (
            "/primitive/sinus/property/amplitude",
            "/primitives/sinus/properties/amplitude/value.json",
        ),
        ("/primitive/sinus/method/list.json", "/primitives/sinus/methods/list.json"),
        ("/motors/list.json", None),
        ("/motor/../robot.json", None),
    ],
)
def test_old_spellings_map_to_the_current_routes(old: str, new: str | None) -> None:
    assert current_path(old) == new


def test_old_spellings_keep_the_errors(client: httpx.Client) -> None:
    assert client.get("/motor/nose/register/present_position").status_code == 404
    assert client.get("/primitive/nope/start.json").status_code == 404
