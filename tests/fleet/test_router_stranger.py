"""The topology users deploy: robots and the teacher's laptop connected only to a Zenoh router
process, and a stranger's session on the same router that listens, answers and replays.

The robots have a token. What a stranger can and cannot do there is docs/fleet.md's "A stranger
on an open router": it reads what is published (states, health, goal streams, descriptions) but
no token; its answers to a robot's ``api`` are not taken by a client holding the token (the
robot signs its answers); what it recorded, replayed later, drives nothing and takes no lease.
"""

from __future__ import annotations

import json
import logging
import threading
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import httpx
import pytest

from poppy_core import zenoh_auth, zenoh_wire
from poppy_core.errors import CommunicationError
from poppy_core.remote.zenoh_client import ZenohClient
from poppy_core.remote.zenoh_fleet import Fleet
from poppy_core.zenoh_wire import ZenohSettings
from tests.helpers.waiting import eventually, http_timeout
from tests.helpers.zenoh_router import Router
from tests.helpers.zenoh_served import TOKEN, Served, fleet_timeout_s

zenoh = pytest.importorskip("zenoh")

FAKE = {"status": 200, "body": [{"name": "m1", "present_position": 99.0}]}
"""What the stranger answers to every ``api`` request it gets."""


class Stranger:
    """A session on the router that records every publication and every query to a robot's
    ``api``, answers those queries (``FAKE``) and claims to be the robot ``ghost``."""

    def __init__(self, router: str, ghost: str = "jr9") -> None:
        self.session = zenoh_wire.open_session(ZenohSettings(connect=(router,)))
        self.published: list[tuple[str, bytes]] = []
        self.queries: list[tuple[str, bytes]] = []
        self._lock = threading.Lock()

        def on_query(query: Any) -> None:
            with self._lock:
                payload = query.payload.to_bytes() if query.payload is not None else b""
                self.queries.append((str(query.key_expr), payload))
            query.reply(query.key_expr, json.dumps(FAKE).encode())

        def on_sample(sample: Any) -> None:
            with self._lock:
                self.published.append((str(sample.key_expr), sample.payload.to_bytes()))

        self._declared = [
            self.session.declare_queryable("poppy/*/api", on_query),
            self.session.declare_subscriber("**", on_sample),
            self.session.liveliness().declare_token(zenoh_wire.robot_key(ghost)),
        ]

    def heard(self, key: str) -> list[bytes]:
        with self._lock:
            return [payload for k, payload in self.published if k == key]

    def asked(self, key: str) -> list[bytes]:
        with self._lock:
            return [payload for k, payload in self.queries if k == key]

    def close(self) -> None:
        for declared in self._declared:
            declared.undeclare()
        self.session.close()  # type: ignore[no-untyped-call]


@pytest.fixture
def jr1(moves: Path, router: Router) -> Iterator[Served]:
    served = Served("jr1", router=router.endpoint)
    try:
        yield served
    finally:
        served.close()


@pytest.fixture
def stranger(router: Router) -> Iterator[Stranger]:
    peer = Stranger(router.endpoint)
    try:
        yield peer
    finally:
        peer.close()


@pytest.fixture
def laptop(router: Router, jr1: Served, stranger: Stranger) -> Iterator[Fleet]:
    settings = ZenohSettings(connect=(router.endpoint,))
    with Fleet(settings, token=TOKEN, timeout_s=fleet_timeout_s()) as fleet:
        assert fleet.wait_for(["jr1", "jr9"], timeout_s=30) == ["jr1", "jr9"]
        yield fleet


def _secrets() -> list[bytes]:
    key = zenoh_auth.key_of(TOKEN)
    return [TOKEN.encode(), key, key.hex().encode()]


def test_a_listening_stranger_reads_what_is_published_but_no_token(
    jr1: Served, stranger: Stranger, laptop: Fleet
) -> None:
    jr1.robot.compliant = False
    laptop.goals("jr1")({"m1": 12.0})
    assert eventually(lambda: abs(jr1.robot.m1.goal_position - 12.0) < 0.5)
    [stop] = laptop.command(["jr1"], "POST", "/api/v1/web/stop", {"then": "hold"}, together=False)
    assert stop.ok, stop.message
    assert eventually(
        lambda: stranger.heard("poppy/jr1/state") and stranger.heard("poppy/jr1/health")
    )
    assert eventually(lambda: stranger.heard("poppy/jr1/goals"))

    # readable without the token: the robot's state, its health, the goals streamed to it,
    # the requests sent to it (signed, not encrypted) and its description
    state = zenoh_wire.unpack_state(stranger.heard("poppy/jr1/state")[-1])
    assert set(state.motors) == {f"m{i}" for i in range(1, 7)}
    assert "ok" in json.loads(stranger.heard("poppy/jr1/health")[-1])
    goals = json.loads(json.loads(stranger.heard("poppy/jr1/goals")[0])["signed"])
    assert goals["goals"] == {"m1": 12.0}
    [request] = stranger.asked("poppy/jr1/api")
    assert json.loads(json.loads(request)["signed"])["path"] == "/api/v1/web/stop"
    described = zenoh_wire.descriptions(stranger.session, fleet_timeout_s())
    assert [m["name"] for m in described["jr1"]["motors"]][:2] == ["m1", "m2"]
    # not readable: the token, or anything the robot answers only to its token's holders
    everything = [p for _, p in stranger.published] + [p for _, p in stranger.queries]
    for payload in everything:
        assert not any(secret in payload for secret in _secrets()), payload
    key = zenoh_wire.robot_key("jr1", "api")
    replies = zenoh_wire.ask(
        stranger.session, key, zenoh_wire.api_request("GET", "/api/v1/motors"), fleet_timeout_s()
    ).wait()
    answers = [json.loads(r.ok.payload.to_bytes()) for r in replies if r.ok is not None]
    robot_answers = [a for a in answers if a != FAKE]  # its own queryable answers it too
    assert [a["status"] for a in robot_answers] == [401]


def test_a_stranger_answering_for_a_robot_is_not_taken_for_it(
    jr1: Served, stranger: Stranger, laptop: Fleet, caplog: pytest.LogCaptureFixture
) -> None:
    caplog.set_level(logging.WARNING, logger="poppy_core.remote.zenoh_client")
    # jr1 answers, and so does the stranger: the laptop takes the robot's answer, says why
    [motors] = laptop.command(["jr1"], "GET", "/api/v1/motors", together=False)
    assert motors.ok and [m["name"] for m in motors.answer][:2] == ["m1", "m2"]
    assert motors.answer != FAKE["body"]
    assert stranger.asked("poppy/jr1/api")  # the stranger did answer
    assert any("not signed by the robot were ignored" in r.getMessage() for r in caplog.records)
    # a robot that is only the stranger (its liveliness token, its answers) is refused
    [ghost] = laptop.command(["jr9"], "POST", "/api/v1/web/stop", {"then": "hold"}, together=False)
    assert not ghost.ok
    assert "no answer signed with the token came (answered: 200)" in ghost.message
    # the remote robot of from_remote (and the LeRobot plugin's zenoh:NAME): the same
    client = ZenohClient("jr1", TOKEN, fleet_timeout_s(), session=laptop.session)
    read = client.request("GET", "/api/v1/motors")
    assert [m["name"] for m in read][:2] == ["m1", "m2"]
    with pytest.raises(CommunicationError, match="no answer signed with the token"):
        ZenohClient("jr9", TOKEN, fleet_timeout_s(), session=laptop.session).request(
            "GET", "/api/v1/motors"
        )


def test_what_a_stranger_recorded_replayed_later_drives_nothing_and_takes_no_lease(
    jr1: Served, stranger: Stranger, laptop: Fleet
) -> None:
    robot, service = jr1.robot, jr1.servers.service
    robot.compliant = False
    laptop.goals("jr1")({"m1": 20.0, "m2": -10.0})
    assert eventually(lambda: abs(robot.m1.goal_position - 20.0) < 0.5)
    assert eventually(lambda: service.leases.labels().get("m1", "").startswith("goal stream"))
    [goto] = laptop.command(
        ["jr1"],
        "POST",
        "/api/v1/gotos",
        {"positions": {"m3": 15}, "duration_s": 0.2},
        together=False,
    )
    assert goto.ok, goto.message
    assert eventually(lambda: stranger.heard("poppy/jr1/goals") and stranger.asked("poppy/jr1/api"))
    goals, request = stranger.heard("poppy/jr1/goals")[0], stranger.asked("poppy/jr1/api")[0]
    # the laptop's stream lapses; then the robot is driven by a move of its own
    assert eventually(lambda: "m1" not in service.leases.labels(), timeout_s=30)
    robot.m1.goal_position = 0.0
    robot.m3.goal_position = 0.0
    refused = node_refusals(jr1)
    put = stranger.session.declare_publisher(zenoh_wire.robot_key("jr1", "goals"))
    try:
        put.put(goals)
        key = zenoh_wire.robot_key("jr1", "api")
        replies = zenoh_wire.ask(stranger.session, key, request, fleet_timeout_s()).wait()
    finally:
        put.undeclare()
    answers = [json.loads(r.ok.payload.to_bytes()) for r in replies if r.ok is not None]
    robot_answers = [a for a in answers if a != FAKE]
    assert robot_answers == [
        {"status": 401, "body": {"detail": "replayed: this message was received before"}}
    ]
    assert eventually(lambda: node_refusals(jr1) > refused)  # the goals: refused, counted
    assert robot.m1.goal_position == pytest.approx(0.0, abs=0.5)
    assert robot.m3.goal_position == pytest.approx(0.0, abs=0.5)
    assert service.leases.labels() == {}  # no lease taken by what was replayed


def node_refusals(served: Served) -> int:
    node = served.servers.zenoh
    assert node is not None
    return int(node.refused_goals)


def test_the_teachers_page_through_the_router_takes_only_the_robots_answers(
    router: Router, jr1: Served, stranger: Stranger
) -> None:
    from poppy_core.server.teacher import TeacherServer

    settings = ZenohSettings(connect=(router.endpoint,))
    with (
        TeacherServer(lambda: Fleet(settings, token=TOKEN), token=TOKEN) as page,
        httpx.Client(
            base_url=page.url,
            headers={"Authorization": f"Bearer {TOKEN}"},
            timeout=http_timeout(30),
        ) as http,
    ):

        def both() -> bool:
            names = {c["name"] for c in http.get("/api/v1/fleet/robots").json()}
            return {"jr1", "jr9"} <= names

        assert eventually(both, timeout_s=30)  # the stranger's liveliness token makes a card
        answer = http.post("/api/v1/fleet/stop", json={"robots": ["jr1", "jr9"]})
        assert answer.status_code == 200, answer.text
        outcomes = {o["name"]: o for o in answer.json()["outcomes"]}
        assert outcomes["jr1"]["ok"] is True
        assert outcomes["jr9"]["ok"] is False
        assert "no answer signed with the token" in outcomes["jr9"]["message"]
    assert stranger.asked("poppy/jr9/api")
