"""Release the motors (ports closed: another process opens them) and take them back (issue 26.4).

The robot is served from an emulated Ergo Jr on a pty (a real serial device for the OS, locked
as a robot's adapter is); the other program is another Python process reading the motors.
"""

from __future__ import annotations

import json
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import httpx
import pytest

from poppy_core import from_profile
from poppy_core.assembly import Listen, ServeSpec, serve
from poppy_core.emulator import Endpoint, serve_pty
from poppy_core.robot import Robot, load_profile
from poppy_core.robot.factory import virtual_buses
from tests.helpers.bus import loaded_reply_floor_s
from tests.helpers.waiting import eventually, http_timeout

TOKEN = "s3cret"
AUTH = {"Authorization": f"Bearer {TOKEN}"}
# another program reading the motors of the bus at PORT: their present positions, or the error
READER = """
import json, sys
from poppy_core.bus import DxlBus
from poppy_core.errors import PoppyError
from poppy_core.models import model_by_name
xl320 = model_by_name("XL-320")
try:
    with DxlBus(sys.argv[1], 1_000_000, 2, min_timeout_s=float(sys.argv[2])) as bus:
        found = {i: bus.read_register(i, xl320, "present_position") for i in range(1, 7)}
except PoppyError as exc:
    print(json.dumps({"error": str(exc)}))
else:
    print(json.dumps({"positions": found}))
"""


def read_from_another_process(port: str) -> dict[str, object]:
    done = subprocess.run(
        [sys.executable, "-c", READER, port, str(loaded_reply_floor_s())],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 0, done.stderr
    answer: dict[str, object] = json.loads(done.stdout)
    return answer


@pytest.fixture
def bus_port(tmp_path: Path) -> Iterator[str]:
    """An Ergo Jr's six XL-320 on a pty, reached through a symlink (as /dev/serial/by-id)."""
    (virtual,) = virtual_buses(load_profile("ergo-jr")).values()
    port = str(tmp_path / "ttyDXL")
    server: Endpoint = serve_pty(virtual, link=port)
    yield port
    server.stop()


@pytest.fixture
def robot(bus_port: str, moves_folder: str) -> Iterator[Robot]:
    with from_profile("ergo-jr", port=bus_port, sensors=False) as built:
        yield built


@pytest.fixture
def client(robot: Robot) -> Iterator[httpx.Client]:
    with serve(robot, ServeSpec(http=Listen(), token=TOKEN)) as servers:
        assert servers.http is not None
        with httpx.Client(
            base_url=servers.http.url, timeout=http_timeout(30.0), headers=AUTH
        ) as http:
            yield http


def test_release_frees_the_port_for_another_process_and_take_gets_it_back(
    bus_port: str, robot: Robot, client: httpx.Client
) -> None:
    robot.dance.start()
    refused = read_from_another_process(bus_port)
    assert "busy" in str(refused.get("error")), refused  # held by the served robot

    released = client.post("/api/v1/motors/release")
    assert released.status_code == 200, released.text
    body = released.json()
    assert body["released"] is True and body["ports"] == [bus_port]
    assert body["primitives"] == ["dance"] and not robot.dance.running
    assert client.get("/api/v1/motors/access").json()["released"] is True

    other = read_from_another_process(bus_port)
    assert sorted(other.get("positions", {})) == ["1", "2", "3", "4", "5", "6"], other
    assert all(m.compliant and not m.online for m in robot.motors)

    taken = client.post("/api/v1/motors/take")
    assert taken.status_code == 200, taken.text
    assert taken.json() == {"released": False, "ports": [bus_port], "no_motors": []}
    assert all(m.online for m in robot.motors)
    assert eventually(lambda: client.get("/api/v1/motors/m3").json()["online"] is True)
    robot.m3.compliant = False
    robot.m3.goal_position = 25.0
    assert eventually(lambda: abs(robot.m3.present_position - 25.0) < 3.0)
    assert "busy" in str(read_from_another_process(bus_port).get("error"))


def test_take_while_another_program_holds_the_port_is_a_conflict(
    bus_port: str, robot: Robot, client: httpx.Client
) -> None:
    from poppy_core.bus import DxlBus

    assert client.post("/api/v1/motors/release").status_code == 200
    with DxlBus(bus_port, 1_000_000, 2):
        refused = client.post("/api/v1/motors/take")
        assert refused.status_code == 409
        assert "busy" in refused.json()["detail"]
        assert client.get("/api/v1/motors/access").json()["released"] is True
    assert client.post("/api/v1/motors/take").status_code == 200
    assert all(m.online for m in robot.motors)


def test_release_and_take_need_the_token(client: httpx.Client, robot: Robot) -> None:
    for route in ("/api/v1/motors/release", "/api/v1/motors/take"):
        assert client.post(route, headers={"Authorization": ""}).status_code == 401
    assert not robot.released


def test_releasing_twice_and_taking_twice_change_nothing(
    client: httpx.Client, robot: Robot
) -> None:
    assert client.post("/api/v1/motors/take").json()["released"] is False
    assert client.post("/api/v1/motors/release").json()["released"] is True
    assert client.post("/api/v1/motors/release").json()["released"] is True
    assert client.post("/api/v1/motors/take").json()["released"] is False
    assert all(m.online for m in robot.motors)
