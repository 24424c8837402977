"""``start_at`` is an explicit argument of the service's starts, over plain HTTP too: a v1 start
or play with one is armed on arrival and started then; one too far from now is refused (422);
a stop before it calls the start off. No hidden channel carries it (each service arms its own)."""

from __future__ import annotations

import time

import httpx
import pytest

from poppy_core.motion.move import Move
from poppy_core.motion.move_library import save_move
from poppy_core.server.errors import ApiError
from poppy_core.server.service import RobotService
from tests.helpers.server import Served
from tests.helpers.waiting import eventually

LEAD_S = 0.5


def test_a_primitive_started_with_a_start_at_runs_then_not_before(
    client: httpx.Client, served: Served
) -> None:
    sinus = served.app.state.service.primitive("sinus")
    began: list[float] = []
    real = sinus.setup

    def spy() -> None:
        began.append(time.time())
        real()

    sinus.setup = spy  # type: ignore[method-assign]
    try:
        when = time.time() + LEAD_S
        answer = client.post("/api/v1/primitives/sinus/start", json={"start_at": when})
        assert answer.status_code == 200, answer.text
        assert eventually(lambda: bool(began))
        assert began[0] >= when - 1e-6  # armed on arrival, run at its start time
    finally:
        client.post("/api/v1/primitives/sinus/stop")
        del sinus.setup  # type: ignore[method-assign]


def test_a_stop_before_the_start_at_means_nothing_starts(
    client: httpx.Client, served: Served
) -> None:
    when = time.time() + LEAD_S
    assert client.post("/api/v1/primitives/square/start", json={"start_at": when}).is_success
    assert client.post("/api/v1/primitives/square/stop").is_success
    time.sleep(max(0.0, when - time.time()) + 0.2)
    assert "square" not in served.app.state.service.running_primitives()


def test_a_start_at_too_far_or_on_a_stop_is_refused(client: httpx.Client, served: Served) -> None:
    for body in ({"start_at": time.time() + 3600}, {"start_at": "soon"}, {"at": 1}):
        answer = client.post("/api/v1/primitives/sinus/start", json=body)
        assert answer.status_code == 422, answer.text
        assert "\n" not in answer.text
    assert "sinus" not in served.app.state.service.running_primitives()
    with pytest.raises(ApiError, match="start_at"):  # the service's rule: only a start takes one
        served.app.state.service.control_primitive("sinus", "stop", start_at=time.time() + 1)


def test_a_move_played_with_a_start_at_is_armed_then_played(
    client: httpx.Client, served: Served
) -> None:
    save_move(Move.from_frames(10.0, [{"m1": 5.0 + i} for i in range(5)]), "armed")
    when = time.time() + LEAD_S
    answer = client.post("/api/v1/moves/armed/play", json={"start_at": when, "ramp_s": 0.2})
    assert answer.status_code == 202, answer.text
    player = served.app.state.service.moves._players["armed"]
    assert player.playing  # its thread is made, held at its gate
    assert eventually(lambda: bool(player.loop_times))
    assert eventually(lambda: not player.playing)
    far = client.post("/api/v1/moves/armed/play", json={"start_at": time.time() + 3600})
    assert far.status_code == 422, far.text


def test_each_service_arms_its_own_starts(served: Served) -> None:
    other = RobotService(served.robot, builtins=False)
    try:
        assert other.starts is not served.app.state.service.starts
        gate = other.starts.gate(time.time() + LEAD_S)
        assert gate is not None
        assert other.starts.armed == 1 and served.app.state.service.starts.armed == 0
        assert gate.wait(10.0)
        assert other.starts.armed == 0
    finally:
        other.close()
