"""Goals to compliant motors (issue 40): the v1 API refuses them with a 409 saying how to make
the motor stiff; pypot's routes keep pypot's answers; the log names each motor once per period
of compliance."""

from __future__ import annotations

import logging
from collections.abc import Iterator

import httpx
import pytest

from tests.helpers.server import Served
from tests.server.test_motor_leases import owners

LOGGER = "poppy_core.server.compliant_goals"


@pytest.fixture
def free(served: Served) -> Iterator[Served]:
    """The served robot, every motor compliant, its goals where they are."""
    served.robot.compliant = True
    yield served
    served.robot.compliant = True


def _warnings(caplog: pytest.LogCaptureFixture) -> list[str]:
    return [r.getMessage() for r in caplog.records if r.name == LOGGER]


def test_v1_refuses_a_goal_to_a_compliant_motor_in_one_line(
    client: httpx.Client, free: Served
) -> None:
    before = free.robot.m1.goal_position
    for answer in (
        client.put("/api/v1/motors/m1/registers/goal_position", json={"value": 20}),
        client.patch("/api/v1/motors", json={"m1": {"goal_position": 20}, "m2": {"led": "red"}}),
        client.post("/api/v1/gotos", json={"positions": {"m1": 20}, "duration_s": 0.5}),
    ):
        assert answer.status_code == 409, answer.text
        (detail,) = answer.json()["detail"].splitlines()
        assert detail.startswith("m1 is compliant (torque off), so a goal would not move it")
        assert "/api/v1/motors/m1/registers/compliant" in detail and "false" in detail
    assert free.robot.m1.goal_position == before
    assert free.robot.m2.led != "red"  # all or nothing


def test_v1_names_every_compliant_motor_of_a_goto(client: httpx.Client, free: Served) -> None:
    free.robot.m1.compliant = False
    answer = client.post(
        "/api/v1/gotos", json={"positions": {"m1": 0, "m2": 5, "m3": 5}, "duration_s": 0.5}
    )
    assert answer.status_code == 409
    assert answer.json()["detail"].startswith("m2, m3 are compliant")


def test_v1_accepts_a_goal_to_a_motor_made_stiff_by_the_same_command(
    client: httpx.Client, free: Served
) -> None:
    answer = client.patch("/api/v1/motors", json={"m1": {"compliant": False, "goal_position": 5}})
    assert answer.status_code == 200, answer.text
    assert not free.robot.m1.compliant
    put = client.put("/api/v1/motors/m1/registers/goal_position", json={"value": 0})
    assert put.status_code == 200
    # waited: a goto still running on a busy machine wrote m1's goal in the next test
    goto = {"positions": {"m1": 0}, "duration_s": 0.2, "wait": True}
    assert client.post("/api/v1/gotos", json=goto).status_code == 200


def test_pypot_routes_keep_pypot_s_answers_and_the_log_says_it_once_per_period(
    client: httpx.Client, free: Served, caplog: pytest.LogCaptureFixture
) -> None:
    caplog.set_level(logging.WARNING, logger=LOGGER)
    for _ in range(3):
        answer = client.post("/motors/m4/registers/goal_position/value.json", content="12.5")
        assert answer.status_code == 202 and answer.json() == {"goal_position": 12.5}
        goto = client.post("/motors/m4/goto.json", json={"position": 10, "duration": 0.1})
        assert goto.status_code == 202
    assert len(_warnings(caplog)) == 1
    assert _warnings(caplog)[0].startswith("m4 is compliant (torque off)")
    client.post("/motors/m4/registers/compliant/value.json", content="false")
    client.post("/motors/m4/registers/goal_position/value.json", content="0")
    client.post("/motors/m4/registers/compliant/value.json", content="true")
    client.post("/motors/m4/registers/goal_position/value.json", content="12.5")
    assert len(_warnings(caplog)) == 2  # a new period of compliance: named again


def test_v1_chain_goto_refuses_compliant_motors_and_pypots_ik_goto_still_writes(
    client: httpx.Client, free: Served
) -> None:
    """A chain goto is a v1 goal as ``POST /api/v1/gotos`` is: one compliant active motor
    refuses it (409, the same line), nothing moved; pypot's IK route keeps pypot's answer."""
    arm = [f"m{i}" for i in range(1, 7)]
    free.robot.compliant = False
    free.robot.m3.compliant = True
    before = {name: free.robot.motor(name).goal_position for name in arm}
    body = {"position": [0.1, -0.1, 0.12], "duration": 0.5}
    for extra in ({}, {"linear": True}):
        answer = client.post("/api/v1/chains/chain/goto", json={**body, **extra})
        assert answer.status_code == 409, answer.text
        (detail,) = answer.json()["detail"].splitlines()
        assert detail.startswith("m3 is compliant (torque off), so a goal would not move it")
    assert {name: free.robot.motor(name).goal_position for name in arm} == before
    assert all(owner is None for owner in owners(client).values())  # a refused goto leases nothing

    pypot = client.post("/ik/chain/goto.json", json={"xyz": body["position"], "duration": "0.5"})
    assert pypot.status_code == 200, pypot.text
