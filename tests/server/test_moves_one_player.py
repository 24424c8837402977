"""A move plays once at a time: two plays at once start one player, and a stop stops it.

Before, the check (is it playing?), the start and the registration of a player were three steps:
two plays of one move at the same time both found it not playing and started two players, and
``stop`` reached only the one registered last, the other one moving the robot on.
"""

from __future__ import annotations

import threading
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import httpx
import pytest

from poppy_core import from_profile
from poppy_core.assembly import Listen, ServeSpec, serve
from poppy_core.motion import Move, save_move
from poppy_core.robot import Robot
from poppy_core.server import moves as moves_module
from poppy_core.server.errors import ApiError
from poppy_core.server.moves import MoveService
from tests.helpers.waiting import eventually, http_timeout

LONG = Move(10.0, ["m1"], [[0.0]] * 600)  # a minute: still playing when the test stops it


@pytest.fixture
def robot(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Robot]:
    monkeypatch.setenv("POPPY_MOVES_DIR", str(tmp_path / "library"))
    save_move(LONG, "long")
    with from_profile("ergo-jr", sim=True) as built:
        yield built


@pytest.fixture
def started(monkeypatch: pytest.MonkeyPatch) -> list[Any]:
    """Every player started, in order."""
    players: list[Any] = []

    class Counted(moves_module.MovePlayer):
        def start(self, **kwargs: Any) -> Any:
            players.append(self)
            return super().start(**kwargs)

    monkeypatch.setattr(moves_module, "MovePlayer", Counted)
    return players


def _together(service: MoveService, monkeypatch: pytest.MonkeyPatch, **options: Any) -> list[Any]:
    """Two plays of ``long`` at once, each loading the move while the other one does (when it
    can: a play that waits for the other's end loads alone); what each answered."""
    inside: list[str] = []
    both = threading.Event()
    load = service.load

    def slow_load(name: str) -> Move:
        inside.append(name)
        if len(inside) == 2:
            both.set()
        both.wait(2.0)  # the window where the old code let the other play in
        return load(name)

    monkeypatch.setattr(service, "load", slow_load)
    answers: list[Any] = [None, None]

    def play(index: int) -> None:
        try:
            answers[index] = service.play("long", **options)
        except ApiError as exc:
            answers[index] = exc

    threads = [threading.Thread(target=play, args=(i,)) for i in (0, 1)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(30)
    return answers


def test_two_plays_at_once_start_one_player_and_stop_stops_it(
    robot: Robot, started: list[Any], monkeypatch: pytest.MonkeyPatch
) -> None:
    service = MoveService(robot)
    answers = _together(service, monkeypatch)
    assert len(started) == 1
    assert answers == [started[0], started[0]]  # pypot's way: the second gets the one playing
    service.stop("long")
    assert eventually(lambda: not any(p.playing for p in started))
    assert service.playing() == []


def test_the_v1_way_refuses_the_second_play(
    robot: Robot, started: list[Any], monkeypatch: pytest.MonkeyPatch
) -> None:
    service = MoveService(robot)
    answers = _together(service, monkeypatch, refuse_playing=True)
    assert len(started) == 1
    refused = [a for a in answers if isinstance(a, ApiError)]
    assert [a for a in answers if a is started[0]] == [started[0]]
    assert len(refused) == 1 and refused[0].kind == "conflict"
    assert "already playing" in str(refused[0])
    assert service.stop_all() == ["long"]
    assert not started[0].playing


def test_nothing_plays_or_records_after_close(robot: Robot, started: list[Any]) -> None:
    service = MoveService(robot)
    service.play("long")
    service.close()
    assert not started[0].playing
    for start in (lambda: service.play("long"), lambda: service.record("take", ["m1"])):
        with pytest.raises(ApiError) as refused:
            start()
        assert refused.value.kind == "unavailable"
    assert len(started) == 1 and service.recording() == []


def test_over_http_a_second_play_is_refused_on_v1_and_left_alone_on_pypots_route(
    robot: Robot, started: list[Any]
) -> None:
    with (
        serve(robot, ServeSpec(http=Listen())) as servers,
        httpx.Client(base_url=servers.http.url, timeout=http_timeout(10.0)) as client,  # type: ignore[union-attr]
    ):
        assert client.post("/api/v1/moves/long/play", json={"speed": 1}).status_code == 202
        again = client.post("/api/v1/moves/long/play", json={"speed": 2})
        assert again.status_code == 409
        assert "already playing: stop it first" in again.json()["detail"]
        pypot = client.post("/records/long/play.json", json={"speed": "1.0"})
        assert pypot.status_code == 202 and pypot.json() == {"long": "started replay"}
        assert len(started) == 1 and started[0].playing
        assert client.post("/api/v1/moves/long/stop").status_code == 200
        assert not started[0].playing
