"""A fleet's shared start time: starts are armed on arrival and fired at ``start_at``.

Order and arrival only (the machine is shared): an armed start runs after its start time, never
before; every armed start fires; a stop before the start time means nothing starts; a refused
command moves nothing.
"""

from __future__ import annotations

import json
import threading
import time
from collections.abc import Iterator
from typing import Any

import pytest

from poppy_core import from_profile, zenoh_wire
from poppy_core.errors import ArgumentError
from poppy_core.motion import Primitive
from poppy_core.motion.move import Move
from poppy_core.motion.move_library import save_move
from poppy_core.motion.player import MovePlayer
from poppy_core.remote.zenoh_client import answer_of
from poppy_core.remote.zenoh_fleet import LEAD_MARGIN, START_LEAD_S, Fleet
from poppy_core.robot import Robot
from poppy_core.schedule import Gate
from poppy_core.server.start_time import StartTimes, check_start_at, wait_until
from tests.helpers.cli import run_poppy
from tests.helpers.waiting import eventually, scaled
from tests.helpers.zenoh_served import TOKEN, Served

LEAD_S = 0.3
PRIMITIVE_START = "/api/v1/primitives/dance/start"


class Stamp(Primitive):
    """Notes when it began running."""

    def __init__(self, robot: Robot) -> None:
        super().__init__(robot)
        self.began: list[float] = []

    def run(self) -> None:
        self.began.append(time.time())


@pytest.fixture
def robot() -> Iterator[Robot]:
    with from_profile("ergo-jr", sim=True) as jr:
        yield jr


def test_without_a_start_time_there_is_no_gate() -> None:
    starts = StartTimes()
    assert starts.gate(None) is None
    assert starts.gate(time.time() - 1.0) is None  # a start time already past: at once
    assert starts.armed == 0


def test_a_start_time_more_than_a_minute_away_is_refused() -> None:
    for off in (-120.0, 120.0):
        with pytest.raises(ArgumentError, match="start_at"):
            check_start_at(time.time() + off)
    with pytest.raises(ArgumentError, match="start_at"):
        check_start_at("soon")
    assert check_start_at(None) is None


def test_armed_primitives_all_fire_after_their_start_time(robot: Robot) -> None:
    stamps = [Stamp(robot) for _ in range(5)]
    when = time.time() + LEAD_S
    starts = StartTimes()
    gates = [starts.gate(when) for _ in stamps]
    for stamp, gate in zip(stamps, gates, strict=True):
        stamp.start(gate=gate)  # armed: its thread is made, held at the gate
    assert not any(s.began for s in stamps) or time.time() >= when
    assert eventually(lambda: all(s.began for s in stamps))
    assert all(s.began[0] >= when for s in stamps)  # fired at the start time, not on arrival
    assert all(len(s.began) == 1 for s in stamps)


def test_a_stop_before_the_start_time_means_the_primitive_never_runs(robot: Robot) -> None:
    stamp = Stamp(robot)
    when = time.time() + LEAD_S
    gate = StartTimes().gate(when)
    assert gate is not None
    stamp.start(gate=gate)
    stamp.stop()  # before the start time
    assert gate.cancelled and stamp.state == "stopped" and not stamp.is_alive()
    wait_until(when + 0.05)
    assert stamp.began == []
    stamp.start()  # it can still be started again, now
    assert eventually(lambda: len(stamp.began) == 1)


def test_a_stopped_armed_move_plays_nothing(robot: Robot) -> None:
    robot.compliant = False
    before = {m.name: m.goal_position for m in robot.motors}
    move = Move.from_frames(10.0, [{"m1": 30.0}, {"m1": 35.0}, {"m1": 40.0}])
    player = MovePlayer(robot, move)
    gate = Gate()
    player.start(gate=gate)
    player.stop()
    gate.open()  # too late: the stop called it off
    assert player.wait(5.0) and player.stopped and player.loop_times == []
    assert {m.name: m.goal_position for m in robot.motors} == before


def test_a_gate_opens_or_is_cancelled_whichever_comes_first() -> None:
    opened, cancelled = Gate(), Gate()
    opened.open()
    opened.cancel()
    cancelled.cancel()
    cancelled.open()
    assert opened.wait(0) and not opened.cancelled
    assert not cancelled.wait(0) and cancelled.cancelled
    held = Gate()
    results: list[bool] = []
    thread = threading.Thread(target=lambda: results.append(held.wait()))
    thread.start()
    held.open()
    thread.join(5.0)
    assert results == [True]


def _send(fleet: Fleet, name: str, path: str, start_at: float | None, body: Any = None) -> Any:
    payload = zenoh_wire.api_request("POST", path, body, token=TOKEN, start_at=start_at, robot=name)
    key = zenoh_wire.robot_key(name, "api")
    return fleet.session.get(key, payload=payload, timeout=scaled(10.0))


def test_a_fleet_stop_before_the_start_time_means_nothing_starts(
    two: tuple[Served, Served], fleet: Fleet
) -> None:
    ran: list[str] = []  # the primitives whose setup (their first step) ran
    for served in two:
        dance = served.servers.service.primitive("dance")
        dance.setup = lambda name=served.name: ran.append(name)  # type: ignore[method-assign]
    start_at = time.time() + min(scaled(2.0), 30.0)  # time to arm and stop, at this load
    started = [_send(fleet, s.name, "/api/v1/primitives/dance/start", start_at) for s in two]
    assert eventually(
        lambda: all("dance" in s.servers.service.running_primitives() for s in two)
    )  # armed on arrival
    stopped = fleet.command(
        ["jr-a", "jr-b"], "POST", "/api/v1/primitives/dance/stop", together=False
    )
    assert [o.ok for o in stopped] == [True, True]
    for handler in started:  # answered when armed
        status, _ = answer_of("zenoh", list(handler), 10.0, 0.0)
        assert status < 400
    wait_until(start_at + 0.1)
    assert ran == []
    assert not any(s.servers.service.running_primitives() for s in two)


def test_a_refused_fleet_play_moves_nothing(two: tuple[Served, Served], fleet: Fleet) -> None:
    a, _ = two
    a.robot.compliant = False
    before = {m.name: m.goal_position for m in a.robot.motors}
    body = {"speed": 1.0, "backwards": False}
    outcomes = fleet.command(["jr-a", "jr-b"], "POST", "/api/v1/moves/nowhere/play", body)
    assert [o.ok for o in outcomes] == [False, False]
    assert all(o.status == 404 for o in outcomes), [(o.status, o.message) for o in outcomes]
    assert fleet.last_start_at is not None
    wait_until(fleet.last_start_at + 0.1)
    assert a.servers.service.moves.playing() == []
    assert {m.name: m.goal_position for m in a.robot.motors} == before


def test_the_fleet_stop_before_the_start_time_cancels_an_armed_move(
    two: tuple[Served, Served], fleet: Fleet, monkeypatch: pytest.MonkeyPatch
) -> None:
    played_from: list[MovePlayer] = []  # the players whose playback (their thread's body) ran
    real_run = MovePlayer._run

    def run(self: MovePlayer, stopping: threading.Event, at: float | None = None) -> None:
        played_from.append(self)
        real_run(self, stopping, at)

    monkeypatch.setattr(MovePlayer, "_run", run)
    wave = Move.from_frames(10.0, [{"m1": 30.0 + i} for i in range(5)])
    save_move(wave, "wave")
    before = {}
    for served in two:
        served.robot.compliant = False
        before[served.name] = {m.name: m.goal_position for m in served.robot.motors}
    start_at = time.time() + min(scaled(2.0), 30.0)  # time to arm and stop, at this load
    body = {"speed": 1.0, "backwards": False}
    played = [_send(fleet, s.name, "/api/v1/moves/wave/play", start_at, body) for s in two]
    assert eventually(lambda: all(s.servers.service.moves.playing() == ["wave"] for s in two))
    stopped = fleet.command(
        ["jr-a", "jr-b"], "POST", "/api/v1/web/stop", {"then": "hold"}, together=False
    )
    assert [o.ok for o in stopped] == [True, True], [o.message for o in stopped]
    for handler in played:
        answer_of("zenoh", list(handler), 10.0, 0.0)
    wait_until(start_at + 0.1)
    assert played_from == []
    for served in two:
        assert served.servers.service.moves.playing() == []
        assert {m.name: m.goal_position for m in served.robot.motors} == before[served.name]


def test_an_armed_start_is_answered_on_arrival_and_says_when_it_starts(
    two: tuple[Served, Served], fleet: Fleet
) -> None:
    a, _ = two
    began: list[float] = []
    dance = a.servers.service.primitive("dance")
    dance.setup = lambda: began.append(time.time())  # type: ignore[method-assign]
    start_at = time.time() + 30.0  # far enough that no loaded machine reaches it first
    handler = _send(fleet, a.name, "/api/v1/primitives/dance/start", start_at)
    replies = list(handler)  # the reply, before the start time
    assert time.time() < start_at
    answer = json.loads(replies[0].ok.payload.to_bytes())
    assert answer["status"] == 200 and answer["start_at"] == pytest.approx(start_at)
    assert began == [] and "dance" in a.servers.service.running_primitives()  # armed
    fleet.command([a.name], "POST", "/api/v1/primitives/dance/stop", together=False)
    assert began == []


def test_a_refused_armed_start_has_no_start_time(two: tuple[Served, Served], fleet: Fleet) -> None:
    a, _ = two
    handler = _send(fleet, a.name, "/api/v1/primitives/nowhere/start", time.time() + 30.0)
    answer = json.loads(next(iter(handler)).ok.payload.to_bytes())
    assert answer["status"] == 404 and "start_at" not in answer


def test_a_together_command_returns_once_its_start_time_came(
    two: tuple[Served, Served], fleet: Fleet
) -> None:
    outcomes = fleet.command(["jr-a", "jr-b"], "POST", "/api/v1/primitives/dance/start")
    assert [o.ok for o in outcomes] == [True, True]
    assert fleet.last_start_at is not None and time.time() >= fleet.last_start_at
    fleet.command(["jr-a", "jr-b"], "POST", "/api/v1/primitives/dance/stop", together=False)


def test_the_gate_of_a_shared_start_carries_its_start_time(robot: Robot) -> None:
    when = time.time() + LEAD_S
    gate = StartTimes().gate(when)
    assert gate is not None and gate.at is not None
    # start_at on the motion's clock (time.monotonic()); the two clocks read a moment apart
    assert gate.at - time.monotonic() == pytest.approx(when - time.time(), abs=0.05)
    stamp = Stamp(robot)
    stamp.start(gate=gate)
    assert stamp.shared_start == gate.at  # the primitive's time counts from the start time
    assert eventually(lambda: stamp.began != [])


def test_fleet_play_with_a_ramp_gives_every_robot_that_ramp(
    two: tuple[Served, Served], fleet: Fleet
) -> None:
    save_move(Move.from_frames(10.0, [{"m1": 30.0 + i} for i in range(5)]), "wave")
    args = [arg for s in two for arg in ("--connect", s.endpoint)]
    result = run_poppy("fleet", "play", "wave", "--all", "--ramp", "1.5", "--token", TOKEN, *args)
    assert result.code == 0, result.stderr
    for served in two:
        player = served.servers.service.moves._players["wave"]
        assert player.ramp_s == 1.5
        player.stop()


def test_a_bad_ramp_is_refused_and_plays_nothing(two: tuple[Served, Served], fleet: Fleet) -> None:
    save_move(Move.from_frames(10.0, [{"m1": 30.0 + i} for i in range(5)]), "wave")
    args = [arg for s in two for arg in ("--connect", s.endpoint)]
    result = run_poppy("fleet", "play", "wave", "--all", "--ramp", "-1", "--token", TOKEN, *args)
    assert result.code == 2 and "--ramp" in result.stderr and "Traceback" not in result.stderr
    body = {"speed": 1.0, "ramp_s": -1}
    outcomes = fleet.command(["jr-a"], "POST", "/api/v1/moves/wave/play", body, together=False)
    assert outcomes[0].status == 422 and "ramp_s" in outcomes[0].message
    assert all(s.servers.service.moves.playing() == [] for s in two)


def test_a_start_time_already_past_starts_at_once_and_says_how_late(
    two: tuple[Served, Served], fleet: Fleet
) -> None:
    """A classroom on a bad Wi-Fi still plays: the robot the command reaches after its start
    time starts at once, answers ok, and says by how much it was late."""
    a, _ = two
    began: list[float] = []
    dance = a.servers.service.primitive("dance")
    dance.setup = lambda: began.append(time.time())  # type: ignore[method-assign]
    start_at = time.time() - 2.0  # the command came two seconds after its start time
    answer = json.loads(
        next(iter(_send(fleet, a.name, PRIMITIVE_START, start_at))).ok.payload.to_bytes()
    )
    assert answer["status"] == 200
    assert answer["late_s"] >= 2.0
    assert eventually(lambda: began != [])  # started, not armed for a time gone
    fleet.command([a.name], "POST", "/api/v1/primitives/dance/stop", together=False)


def test_fleet_play_with_no_lead_plays_on_every_robot_and_says_how_late(
    two: tuple[Served, Served], fleet: Fleet
) -> None:
    save_move(Move.from_frames(10.0, [{"m1": 30.0 + i} for i in range(5)]), "wave")
    args = [arg for s in two for arg in ("--connect", s.endpoint)]
    result = run_poppy(
        "fleet", "play", "wave", "--all", "--lead", "0", "--token", TOKEN, "--json", *args
    )
    assert result.code == 0, result.stderr
    rows = {row["name"]: row for row in result.json()}
    assert all(row["ok"] and row["late_s"] > 0 for row in rows.values()), rows
    result = run_poppy("fleet", "stop", "--all", "--token", TOKEN, *args)
    assert result.code == 0, result.stderr
    outcomes = fleet.command(["jr-a"], "POST", PRIMITIVE_START, lead_s=0.0)
    assert outcomes[0].ok and outcomes[0].late_s > 0
    fleet.command(["jr-a"], "POST", "/api/v1/primitives/dance/stop", together=False)


def test_the_start_lead_follows_the_slowest_robot_s_round_trip(
    two: tuple[Served, Served], fleet: Fleet
) -> None:
    assert fleet.start_lead(["jr-a", "jr-b"]) >= START_LEAD_S  # the floor on a quick network
    b = two[1].servers.zenoh
    assert b is not None
    described = b.description

    def slow() -> dict[str, Any]:  # a robot on a bad Wi-Fi: half a second to answer
        time.sleep(0.5)
        return described()

    b.description = slow  # type: ignore[method-assign]
    outcomes = fleet.command(["jr-a", "jr-b"], "POST", PRIMITIVE_START)
    assert [o.ok for o in outcomes] == [True, True]
    assert fleet.last_lead_s is not None and fleet.last_lead_s >= 0.5 * LEAD_MARGIN
    fleet.command(["jr-a", "jr-b"], "POST", "/api/v1/primitives/dance/stop", together=False)
