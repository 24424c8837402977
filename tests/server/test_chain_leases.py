"""The v1 chain gotos follow the one-owner rule (``motion/leases.py``) as the v1 gotos do: a
chain goto on a motor another owner drives is refused (409, the same line), and while it runs
it leases its motors (``chain arm goto from ADDRESS``) until it ends or the robot-wide stop;
pypot's IK goto keeps pypot's semantics (never refused, no lease).

Before, the chain routes skipped the service's goal step: a chain goto while a move played was
started, and a v1 goal for a motor the chain goto drove was taken.
"""

from __future__ import annotations

import threading
from collections.abc import Iterator
from pathlib import Path

import httpx
import pytest

from poppy_core import from_profile
from poppy_core.assembly import Listen, ServerSet, ServeSpec, serve
from poppy_core.motion import Move, save_move
from tests.helpers.waiting import eventually, http_timeout
from tests.server.test_motor_leases import owners, put_goal

LONG = Move(10.0, ["m1", "m2"], [[0.0, 0.0]] * 600)  # a minute: still playing when stopped
TARGET = [0.1, -0.1, 0.12]  # metres, in reach of the Ergo Jr's arm
ARM = ["m1", "m2", "m3", "m4", "m5", "m6"]
HELD = "chain arm goto from 127.0.0.1"


@pytest.fixture
def served(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[ServerSet]:
    monkeypatch.setenv("POPPY_MOVES_DIR", str(tmp_path / "library"))
    save_move(LONG, "long")
    with from_profile("ergo-jr", sim=True) as robot, serve(robot, ServeSpec(http=Listen())) as s:
        robot.compliant = False
        yield s


@pytest.fixture
def http(served: ServerSet) -> Iterator[httpx.Client]:
    assert served.http is not None
    with httpx.Client(base_url=served.http.url, timeout=http_timeout(20.0)) as client:
        yield client


def chain_goto(http: httpx.Client, duration: float, **extra: object) -> httpx.Response:
    body = {"position": TARGET, "duration": duration, **extra}
    return http.post("/api/v1/chains/chain/goto", json=body)


def test_a_move_refuses_a_v1_chain_goto_and_pypots_ik_goto_still_moves(
    http: httpx.Client, served: ServerSet
) -> None:
    robot = served.service.robot
    assert http.post("/api/v1/moves/long/play", json={"speed": 1}).status_code == 202
    before = {name: robot.motor(name).goal_position for name in ARM}

    refused = chain_goto(http, 1.0)
    assert refused.status_code == 409, refused.text
    assert refused.json()["detail"] == (
        "m1, m2 are driven by move long from 127.0.0.1: stop it first "
        "(POST /api/v1/moves/long/stop)"
    )
    linear = chain_goto(http, 1.0, linear=True)
    assert linear.status_code == 409 and "m1, m2 are driven by move long" in linear.text
    for name in ARM[2:]:  # nothing moved
        assert robot.motor(name).goal_position == pytest.approx(before[name], abs=1.0)
    assert owners(http)["m3"] is None  # a refused goto takes no lease

    # pypot's IK route writes as pypot does: the motors the move does not drive go
    pypot = http.post("/ik/chain/goto.json", json={"xyz": TARGET, "duration": "0.5"})
    assert pypot.status_code == 200, pypot.text

    def moved() -> bool:
        return any(abs(robot.motor(n).goal_position - before[n]) > 1.0 for n in ARM[2:])

    assert eventually(moved)
    shown = owners(http)
    assert shown["m1"] == "move long from 127.0.0.1" and shown["m3"] is None


def test_a_v1_chain_goto_leases_its_motors_until_it_ends(
    http: httpx.Client, served: ServerSet
) -> None:
    started = chain_goto(http, 30.0)  # still running when checked (replaced below)
    assert started.status_code == 200, started.text
    assert owners(http) == dict.fromkeys(ARM, HELD)

    refused = put_goal(http, "m3", 10.0)
    assert refused.status_code == 409
    assert refused.json()["detail"] == (
        f"m3 is driven by {HELD}: stop it first (POST /api/v1/web/stop)"
    )
    goto = http.post("/api/v1/gotos", json={"positions": {"m1": 5}, "duration_s": 0.5})
    assert goto.status_code == 409 and f"m1 is driven by {HELD}" in goto.text
    play = http.post("/api/v1/moves/long/play", json={"speed": 1})
    assert play.status_code == 409 and f"m1, m2 are driven by {HELD}" in play.text
    # pypot's register route still writes (last write wins)
    pypot = http.post("/motors/m6/registers/goal_position/value.json", json=3.0)
    assert pypot.status_code == 202, pypot.text
    # the same client's next goto of the chain replaces the running one, as a goto does
    again = chain_goto(http, 1.0, wait=True)
    assert again.status_code == 200 and again.json()["waited"] is True, again.text

    assert eventually(lambda: owners(http) == dict.fromkeys(ARM), timeout_s=20.0)
    assert put_goal(http, "m3", 10.0).status_code == 200


def test_the_robot_wide_stop_ends_a_straight_chain_goto_and_its_lease(
    http: httpx.Client, served: ServerSet
) -> None:
    def streaming() -> bool:  # the thread sending the straight move's waypoints
        return any(t.name == "goto_linear chain" for t in threading.enumerate())

    started = chain_goto(http, 10.0, linear=True)
    assert started.status_code == 200, started.text
    assert owners(http)["m1"] == HELD
    assert streaming()

    stop = http.post("/api/v1/web/stop", json={"then": "hold"})
    assert stop.status_code == 200, stop.text
    assert owners(http) == dict.fromkeys(ARM)
    assert put_goal(http, "m1", 5.0).status_code == 200
    assert not streaming()  # the stop returned once the waypoints stopped
