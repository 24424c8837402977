"""A fleet that trusts no stranger: signed requests on Zenoh, refused replays, impostors that
learn nothing, and a robot that answers every request on arrival.

A stranger here is a Zenoh session on loopback that the fleet's client also connects to (a
classmate's laptop on the same network): it answers ``poppy/*/api`` and listens to every key.
"""

from __future__ import annotations

import asyncio
import gc
import hashlib
import hmac
import json
import logging
import os
import re
import threading
import time
from collections.abc import Iterator
from typing import Any

import pytest

from poppy_core import zenoh_auth, zenoh_wire
from poppy_core.remote.zenoh_fleet import Fleet
from poppy_core.zenoh_wire import ZenohSettings as Settings
from tests.helpers.waiting import eventually
from tests.helpers.zenoh_served import TOKEN, Served, fleet_timeout_s, free_endpoint

zenoh = pytest.importorskip("zenoh")


class Stranger:
    """A Zenoh peer that answers every robot's ``api`` and records all it receives."""

    def __init__(self) -> None:
        self.endpoint = free_endpoint()
        self.session = zenoh_wire.open_session(Settings(listen=(self.endpoint,)))
        self.received: list[bytes] = []
        self._lock = threading.Lock()

        def on_query(query: Any) -> None:
            with self._lock:
                self.received.append(query.payload.to_bytes() if query.payload else b"")
            query.reply(query.key_expr, json.dumps({"status": 200, "body": None}).encode())

        def on_sample(sample: Any) -> None:
            with self._lock:
                self.received.append(sample.payload.to_bytes())

        self._declared = [
            self.session.declare_queryable("poppy/*/api", on_query),
            self.session.declare_subscriber("**", on_sample),
        ]

    def captured(self) -> list[bytes]:
        with self._lock:
            return list(self.received)

    def close(self) -> None:
        for declared in self._declared:
            declared.undeclare()
        self.session.close()


@pytest.fixture
def stranger() -> Iterator[Stranger]:
    peer = Stranger()
    try:
        yield peer
    finally:
        peer.close()


def _ask(session: Any, robot: str, payload: bytes, timeout_s: float = 10.0) -> dict[str, Any]:
    replies = list(
        session.get(zenoh_wire.robot_key(robot, "api"), payload=payload, timeout=timeout_s)
    )
    oks = [json.loads(r.ok.payload.to_bytes()) for r in replies if r.ok is not None]
    assert oks, [r.err.payload.to_bytes() for r in replies if r.err is not None]
    return oks[0]


def _signed_at(stamp: float, robot: str, message: dict[str, Any], token: str = TOKEN) -> bytes:
    """A message signed with ``token`` as if at ``stamp`` (a clock far off, a kept request)."""
    text = json.dumps({**message, "robot": robot, "t": stamp, "nonce": os.urandom(16).hex()})
    mac = hmac.new(zenoh_auth.key_of(token), text.encode(), hashlib.sha256).hexdigest()
    return json.dumps({"signed": text, "mac": mac}).encode()


def test_a_stranger_answering_the_api_learns_nothing_that_drives_a_robot(
    two: tuple[Served, Served], stranger: Stranger
) -> None:
    a, b = two
    a.robot.compliant = False
    endpoints = (a.endpoint, b.endpoint, stranger.endpoint)
    with Fleet(Settings(connect=endpoints), token=TOKEN, timeout_s=fleet_timeout_s()) as fleet:
        assert fleet.wait_for(["jr-a", "jr-b"]) == ["jr-a", "jr-b"]
        outcomes = fleet.command(
            ["jr-a"], "POST", "/api/v1/web/stop", {"then": "hold"}, together=False
        )
        assert [o.status for o in outcomes] == [200]
        send = fleet.goals("jr-b")
        b.robot.compliant = False
        send({"m1": 12.0})
        assert eventually(lambda: abs(b.robot.m1.goal_position - 12.0) < 0.5)
        assert eventually(lambda: len(stranger.captured()) >= 2)
    captured = stranger.captured()
    requests = [p for p in captured if b'"signed"' in p]
    assert len(requests) >= 2  # the command and the goals: both seen by the stranger
    secrets = [TOKEN.encode(), zenoh_auth.key_of(TOKEN), zenoh_auth.key_of(TOKEN).hex().encode()]
    for payload in captured:
        assert not any(secret in payload for secret in secrets), payload
    # what the stranger got does not drive a robot: replayed, it is refused and nothing moves
    a.robot.compliant = False
    with Fleet(Settings(connect=(a.endpoint,)), timeout_s=fleet_timeout_s()) as plain:
        for payload in requests:
            answer = _ask(plain.session, "jr-a", payload)
            assert answer["status"] == 401, answer
            assert (
                "replayed" in answer["body"]["detail"]
                or "signed for robot" in answer["body"]["detail"]
            )
    assert not a.robot.compliant


def test_a_request_kept_stale_or_for_another_robot_or_badly_signed_is_refused(
    two: tuple[Served, Served],
) -> None:
    a, _ = two
    a.robot.compliant = False
    compliant = {"method": "PUT", "path": "/api/v1/robot/compliant", "body": {"compliant": True}}
    with Fleet(Settings(connect=(a.endpoint,)), timeout_s=fleet_timeout_s()) as plain:
        session = plain.session
        for_b = zenoh_wire.api_request(
            "PUT", compliant["path"], compliant["body"], token=TOKEN, robot="jr-b"
        )
        answer = _ask(session, "jr-a", for_b)
        assert answer == {
            "status": 401,
            "body": {"detail": "signed for robot 'jr-b': this is 'jr-a'"},
        }
        stale = _ask(session, "jr-a", _signed_at(time.time() - 120, "jr-a", compliant))
        assert stale["status"] == 401
        # +120 s, or a second or more later if the request waited for a core on the way
        assert re.match(r"stale: signed \+1[2-9]\d s", stale["body"]["detail"]), stale
        ahead = _ask(session, "jr-a", _signed_at(time.time() + 120, "jr-a", compliant))
        assert ahead["status"] == 401 and "stale" in ahead["body"]["detail"]
        wrong = _ask(session, "jr-a", _signed_at(time.time(), "jr-a", compliant, token="guess"))
        assert wrong == {
            "status": 401,
            "body": {"detail": "wrong signature: missing or wrong token"},
        }
        in_clear = json.dumps({**compliant, "token": TOKEN}).encode()
        clear = _ask(session, "jr-a", in_clear)
        assert clear["status"] == 401 and "in clear" in clear["body"]["detail"]
        unsigned = _ask(session, "jr-a", json.dumps(compliant).encode())
        assert unsigned["status"] == 401 and "token" in unsigned["body"]["detail"]
        assert not a.robot.compliant  # nothing of these moved the robot
        # the same request, fresh and signed for jr-a, is taken, once
        good = zenoh_wire.api_request(
            "PUT", compliant["path"], compliant["body"], token=TOKEN, robot="jr-a"
        )
        assert _ask(session, "jr-a", good)["status"] == 200
        assert a.robot.compliant
        again = _ask(session, "jr-a", good)
        assert again == {
            "status": 401,
            "body": {"detail": "replayed: this message was received before"},
        }


def test_the_nonces_remembered_are_bounded() -> None:
    verifier = zenoh_auth.Verifier(TOKEN, "jr-a", max_nonces=3)
    for _ in range(3):
        verifier.open(json.loads(zenoh_auth.sign(TOKEN, "jr-a", {"goals": {}})))
    with pytest.raises(zenoh_auth.Refused) as refused:
        verifier.open(json.loads(zenoh_auth.sign(TOKEN, "jr-a", {"goals": {}})))
    assert refused.value.status == 429 and verifier.remembered == 3


def test_unauthenticated_armed_starts_are_refused_on_arrival_not_at_their_start_time(
    two: tuple[Served, Served],
) -> None:
    """300 starts without the token, due 50 s ahead: each is answered 401 on arrival (before
    the issue they were all held until their start time); nothing is held meanwhile."""
    a, _ = two
    node = a.servers.zenoh
    assert node is not None and node._caller is not None
    start_at = time.time() + 50.0
    payload = zenoh_wire.api_request("POST", "/api/v1/primitives/dance/start", start_at=start_at)
    key = zenoh_wire.robot_key("jr-a", "api")
    with Fleet(Settings(connect=(a.endpoint,)), timeout_s=fleet_timeout_s()) as plain:
        handlers = [plain.session.get(key, payload=payload, timeout=45.0) for _ in range(300)]
        statuses = []
        for handler in handlers:
            replies = [r for r in handler if r.ok is not None]
            statuses.append(json.loads(replies[0].ok.payload.to_bytes())["status"])
        answered = time.time()
    assert statuses == [401] * 300
    assert answered < start_at  # every answer came before the start time they named
    assert node.intake.held == 0
    loop = node._caller.loop
    tasks = asyncio.run_coroutine_threadsafe(_tasks(), loop).result(10)
    assert tasks <= 1  # nothing pending but the counting itself
    assert "dance" not in a.servers.service.running_primitives()


async def _tasks() -> int:
    return len(asyncio.all_tasks())


def test_requests_held_for_a_start_time_are_capped_and_answered_when_the_robot_stops(
    moves: Any, caplog: pytest.LogCaptureFixture
) -> None:
    """The places for requests held until their start time are few; the next is refused with
    429 at once; stopping the robot answers those held (503) and leaves no task pending."""
    served = Served("jr-c")
    node = served.servers.zenoh
    assert node is not None
    node.intake.max_armed = 4
    start_at = time.time() + 40.0
    key = zenoh_wire.robot_key("jr-c", "api")
    try:
        with Fleet(Settings(connect=(served.endpoint,)), timeout_s=fleet_timeout_s()) as plain:
            handlers = []
            for _ in range(4):
                payload = zenoh_wire.api_request(
                    "GET", "/api/v1/motors", token=TOKEN, start_at=start_at, robot="jr-c"
                )
                handlers.append(plain.session.get(key, payload=payload, timeout=30.0))
            assert eventually(lambda: node.intake.held == 4)
            fifth = zenoh_wire.api_request(
                "GET", "/api/v1/motors", token=TOKEN, start_at=start_at, robot="jr-c"
            )
            refused = _ask(plain.session, "jr-c", fifth)
            assert refused["status"] == 429
            assert "4 requests are already waiting" in refused["body"]["detail"]
            caplog.set_level(logging.ERROR, logger="asyncio")
            served.close()
            held = []
            for handler in handlers:
                replies = [r for r in handler if r.ok is not None]
                held.append(json.loads(replies[0].ok.payload.to_bytes()))
        assert held == [{"status": 503, "body": {"detail": "the robot is stopping"}}] * 4
        gc.collect()
        assert not [r for r in caplog.records if "destroyed" in r.getMessage()]
    finally:
        served.close()


def test_a_route_that_raises_is_answered_500_with_its_line(
    two: tuple[Served, Served], fleet: Fleet
) -> None:
    a, _ = two

    def broken() -> Any:
        raise RuntimeError("the groups are gone")

    a.servers.service.groups = broken  # type: ignore[method-assign]
    (outcome,) = fleet.command(["jr-a"], "GET", "/api/v1/groups", together=False)
    assert outcome.status == 500
    # REST's own 500 (the same line as over HTTP), where the robot was silent before
    assert outcome.message == "internal error (RuntimeError): the server's log has the details"


def test_a_raising_publish_tick_is_logged_once_shown_in_health_and_recovers(
    two: tuple[Served, Served], fleet: Fleet, caplog: pytest.LogCaptureFixture
) -> None:
    a, _ = two
    node = a.servers.zenoh
    assert node is not None
    real = node.state_message
    failing = threading.Event()
    failing.set()

    def flaky() -> bytes:
        if failing.is_set():
            raise OSError("the bus went away")
        return real()

    caplog.set_level(logging.WARNING, logger="poppy_core.schedule")
    health: list[dict[str, Any]] = []
    fleet.on_health(lambda name, data: health.append(data) if name == "jr-a" else None)
    node.state_message = flaky  # type: ignore[method-assign]
    assert eventually(lambda: node.state_loop.failures >= 3)
    assert eventually(lambda: any(not h["ok"] and h["publishing"]["failures"] for h in health))
    assert node.running  # the loop lives on: `poppy serve` is not taken down
    failing.clear()
    seen: list[int] = []
    fleet.on_state(lambda name, state: seen.append(state.seq), name="jr-a")
    assert eventually(lambda: len(seen) >= 5, timeout_s=10)
    assert not node.state_loop.failing and node.state_loop.last_error is None
    warned = [r for r in caplog.records if "a tick failed" in r.getMessage()]
    assert len(warned) == 1 and "the bus went away" in warned[0].getMessage()


def test_sigterm_with_a_held_request_answers_it_and_ends_cleanly(moves: Any) -> None:
    """`poppy serve --zenoh` stopped by SIGTERM while a request waits for its start time: the
    request is answered 503, and asyncio reports no task destroyed while pending."""
    import signal
    import subprocess

    from tests.helpers.cli import POPPY, command_env
    from tests.helpers.processes import read_until, reap

    endpoint = free_endpoint()
    argv = [*POPPY, "serve", "--zenoh", "--name", "jr-t", "--zenoh-listen", endpoint]
    proc = subprocess.Popen(
        [*argv, "--token", TOKEN, "--profile", "ergo-jr", "--sim"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env=dict(os.environ, **command_env()),
    )
    try:
        assert proc.stdout is not None and proc.stderr is not None
        assert "poppy/jr-t" in read_until(proc.stdout.fileno(), "poppy/jr-t", 60, proc)
        with Fleet(Settings(connect=(endpoint,)), timeout_s=fleet_timeout_s()) as plain:
            assert plain.wait_for(["jr-t"], timeout_s=30) == ["jr-t"]
            held = zenoh_wire.api_request(
                "GET", "/api/v1/motors", token=TOKEN, start_at=time.time() + 30, robot="jr-t"
            )
            handler = plain.session.get("poppy/jr-t/api", payload=held, timeout=25.0)

            def holding() -> bool:  # the request reached the robot and waits there
                described = plain.describe(["jr-t"]).get("jr-t", {})
                return bool(described.get("health", {}).get("held"))

            assert eventually(holding)
            proc.send_signal(signal.SIGTERM)
            replies = [json.loads(r.ok.payload.to_bytes()) for r in handler if r.ok is not None]
        assert replies == [{"status": 503, "body": {"detail": "the robot is stopping"}}]
        assert proc.wait(30) == 0
        stderr = proc.stderr.read().decode(errors="replace")
        assert "stopped" in stderr
        assert "Task was destroyed" not in stderr, stderr
    finally:
        reap(proc)
