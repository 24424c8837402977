"""Teleoperation of a robot served by ``poppy serve``: the WebSocket, the watchdog, reconnects."""

from __future__ import annotations

import itertools
import json
import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any
from urllib.parse import urlsplit

import pytest
from websockets.sync.client import connect

from bench.link_proxy import LinkProxy
from poppy_core.errors import ConfigError
from poppy_core.motion.teleop.session import teleoperate
from poppy_core.remote import RemoteFollower
from poppy_core.robot import Robot
from poppy_core.server import ServerThread, create_app
from tests.helpers.robots import sim_ergo_jr as ergo_jr
from tests.teleop.hands import wait_for
from tests.teleop.test_teleoperate import Waving


@dataclass
class Served:
    robot: Robot
    app: Any
    url: str
    proxy: LinkProxy

    def states(self) -> dict[str, str]:
        """Motor -> the state of the server's teleoperation session driving it."""
        return dict(self.app.state.service.teleop.states())


def serve(token: str | None = None) -> Iterator[Served]:
    with ergo_jr() as robot:
        app = create_app(robot, token=token)
        server = ServerThread(app).start()
        parts = urlsplit(server.url)
        proxy = LinkProxy(parts.hostname or "127.0.0.1", parts.port or 80)
        try:
            yield Served(robot, app, server.url, proxy)
        finally:
            proxy.close()
            server.stop()


@pytest.fixture
def served() -> Iterator[Served]:
    """A simulated Ergo Jr served over HTTP, reached through a proxy whose link can drop."""
    yield from serve()


def test_a_served_robot_follows_over_the_websocket(leader: Robot, served: Served) -> None:
    follower = RemoteFollower(served.proxy.url, rate_hz=50)
    assert follower.motor_names == [f"m{i}" for i in range(1, 7)]
    with (
        Waving(leader, ["m1", "m2"]),
        teleoperate(leader, follower, "m1=m1, m2=m2", rate_hz=50) as teleop,
    ):
        assert wait_for(lambda: teleop.status().state == "following", timeout_s=5.0)
        assert served.states() == {"m1": "following", "m2": "following"}
        time.sleep(0.3)
        gap = abs(served.robot.m1.goal_position - leader.m1.present_position)
        assert gap < 6.0
        assert set(follower.positions()) == {"m1", "m2"}  # from the state stream
    assert served.states() == {}  # stopped: the motors are free for another client
    assert not served.robot.m1.compliant  # held where it is, stiff


def test_a_stalled_link_holds_the_follower_then_it_resumes_with_a_ramp(
    leader: Robot, served: Served
) -> None:
    follower = RemoteFollower(served.proxy.url, rate_hz=50)
    with (
        Waving(leader, ["m1"], 40.0) as waving,
        teleoperate(leader, follower, "m1=m1", rate_hz=50) as teleop,
    ):
        assert wait_for(lambda: served.states().get("m1") == "following", timeout_s=5.0)
        served.proxy.pause()  # nothing gets through; the connection stays open
        assert wait_for(lambda: served.states().get("m1") == "held", timeout_s=3.0)
        held = served.robot.m1.goal_position
        time.sleep(0.4)
        assert served.robot.m1.goal_position == held  # the leader moves on, the follower holds
        waving.amplitude = 0.0  # the hand waits at 15°, away from where the follower held
        goals: list[float] = []
        served.proxy.resume()
        deadline = time.monotonic() + 4.0
        while time.monotonic() < deadline and served.states().get("m1") != "following":
            goals.append(served.robot.m1.goal_position)
            time.sleep(0.01)
        assert served.states().get("m1") == "following"
        assert wait_for(lambda: abs(served.robot.m1.goal_position - 15.0) < 2.0)
        assert wait_for(lambda: teleop.status().state == "following", timeout_s=5.0)
    steps = [abs(b - a) for a, b in itertools.pairwise(goals)]
    assert max(steps, default=0.0) < 12.0  # ramped back, no jump


def test_a_cut_link_holds_at_once_and_the_client_reconnects(leader: Robot, served: Served) -> None:
    follower = RemoteFollower(served.proxy.url, rate_hz=50)
    with Waving(leader, ["m1"]), teleoperate(leader, follower, "m1=m1", rate_hz=50) as teleop:
        assert wait_for(lambda: served.states().get("m1") == "following", timeout_s=5.0)
        served.proxy.cut()  # the server sees the connection close
        assert wait_for(lambda: follower.reconnects >= 1, timeout_s=10.0)
        assert wait_for(lambda: served.states().get("m1") == "following", timeout_s=10.0)
        assert wait_for(lambda: teleop.status().state == "following", timeout_s=5.0)


@pytest.fixture
def served_with_token() -> Iterator[Served]:
    """The same, with a token."""
    yield from serve(token="s3cret")


def test_the_token_is_needed(served_with_token: Served) -> None:
    served = served_with_token
    with pytest.raises(ConfigError, match="refused the token"):
        RemoteFollower(served.url)
    follower = RemoteFollower(served.url, token="s3cret")
    follower.start(["m3"])
    assert wait_for(lambda: served.states() == {"m3": "held"})
    follower.stop()
    assert served.states() == {}


def _ask(ws: Any, message: dict[str, Any]) -> dict[str, Any]:
    """Send a typed message and return the next answer (not a state frame or a state change)."""
    ws.send(json.dumps(message))
    while True:
        data = json.loads(ws.recv(timeout=5))
        if "error" in data or data.get("type") not in (None, "teleop.state"):
            return dict(data)


def test_websocket_messages_are_checked(served: Served) -> None:
    ws_url = served.url.replace("http://", "ws://") + "/api/v1/ws?rate_hz=5"
    with connect(ws_url) as ws, connect(ws_url) as other:
        assert (
            "send teleop.start first"
            in _ask(ws, {"type": "teleop.goals", "positions": {"m1": 1}})["error"]
        )
        assert "unknown message type" in _ask(ws, {"type": "teleop.dance"})["error"]
        assert "no motor m9" in _ask(ws, {"type": "teleop.start", "motors": ["m9"]})["error"]
        assert "watchdog_s" in _ask(ws, {"type": "teleop.start", "watchdog_s": 60})["error"]
        started = _ask(ws, {"type": "teleop.start", "motors": ["m1", "m2"]})
        assert started["type"] == "teleop.started" and started["motors"] == ["m1", "m2"]
        assert set(started["positions"]) == {"m1", "m2"}
        taken = _ask(other, {"type": "teleop.start", "motors": ["m2", "m3"]})
        assert "m2 is driven by teleop from 127.0.0.1" in taken["error"]
        for bad, words in [
            ({"m3": 1.0}, "'m3' is not teleoperated"),
            ({"m1": "up"}, "m1 must be a number"),
            ({"m1": True}, "m1 must be a number"),
            ([1, 2], "positions must be an object"),
        ]:
            answer = _ask(ws, {"type": "teleop.goals", "positions": bad})
            assert words in answer["error"] and "\n" not in answer["error"]
        assert _ask(ws, {"type": "teleop.stop"})["type"] == "teleop.stopped"
        again = _ask(other, {"type": "teleop.start", "motors": ["m2", "m3"]})
        assert again["type"] == "teleop.started"
        # the pypot-style register commands still work on the same socket
        ws.send(json.dumps({"m4": {"led": "green"}}))
        assert wait_for(lambda: served.robot.m4.led == "green", timeout_s=3.0)


def test_closing_while_reconnecting_joins_every_follower_thread(
    leader: Robot, served: Served
) -> None:
    follower = RemoteFollower(served.proxy.url, rate_hz=50)
    teleop = teleoperate(leader, follower, "m1=m1", rate_hz=50)
    try:
        assert wait_for(lambda: served.states().get("m1") == "following", timeout_s=5.0)
        served.proxy.cut()
        served.proxy.close()  # nothing listens any more: the follower keeps trying
        assert wait_for(lambda: "teleop reconnect" in _thread_names(), timeout_s=10.0)
    finally:
        teleop.stop()
    names = {"teleop", "teleop send", "teleop ws", "teleop reconnect"}
    # every thread ends (stop's joins are bounded: on a busy machine the last may end just after)
    assert wait_for(lambda: not _thread_names() & names, timeout_s=10.0), _thread_names() & names
    assert teleop.error is None


def _thread_names() -> set[str]:
    return {thread.name for thread in threading.enumerate()}
