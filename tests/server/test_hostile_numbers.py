"""One table of hostile numbers (NaN, infinities, 1e309, huge integers, 1e-300, 0) through every
surface: REST (v1 and pypot's routes), the WebSocket, Snap!, ZMQ and the CLI.

Each is refused with a clear one-line 4xx, a WebSocket error frame, a ZMQ ``{"error"}`` or a CLI
error naming what was wrong; never a 500, a closed connection, a primitive that accepts the value
and dies, or a loop that spins. The rules live once in ``poppy_core.checks``.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import Any

import httpx
import pytest
from websockets.sync.client import connect

from poppy_core import from_profile
from poppy_core.robot import Robot
from poppy_core.server import ServerThread, create_app
from poppy_core.server.snap import start_snap_server
from poppy_core.server.zmqserver import start_zmq_server
from tests.helpers.cli import run_poppy
from tests.helpers.waiting import http_timeout

HUGE = "9" * 400
"""An integer JSON parses and ``float()`` cannot hold (OverflowError)."""
VERY_HUGE = "9" * 4000
IK_XYZ_HUGE = '{"xyz": [HUGE, 0, 0], "duration": 1}'.replace("HUGE", HUGE)
IK_DURATION_HUGE = '{"xyz": [0.1, 0, 0.1], "duration": HUGE}'.replace("HUGE", HUGE)


@dataclass
class Surfaces:
    """One virtual Ergo Jr served over REST (with its WebSocket), Snap! and ZMQ."""

    robot: Robot
    http: httpx.Client
    ws_url: str
    snap: httpx.Client
    zmq: Any


@dataclass(frozen=True)
class Refusal:
    """How a surface refused: ``ok`` when it is a clear refusal, and its text."""

    ok: bool
    text: str


@pytest.fixture(scope="module")
def surfaces(moves_folder: str) -> Iterator[Surfaces]:
    robot = from_profile("ergo-jr", sim=True)
    server = ServerThread(create_app(robot)).start()
    snap = start_snap_server(robot, port=0)
    zmq = start_zmq_server(robot, port=0, start=False)  # requests are answered by reply_to
    try:
        with (
            httpx.Client(base_url=server.url, timeout=http_timeout(20.0)) as http,
            httpx.Client(
                base_url=f"http://127.0.0.1:{snap.port}", timeout=http_timeout(20.0)
            ) as snap_http,
        ):
            ws_url = server.url.replace("http://", "ws://") + "/api/v1/ws"
            yield Surfaces(robot, http, ws_url, snap_http, zmq)
    finally:
        zmq.stop()
        snap.stop()
        server.stop()
        robot.close()


# -- how each surface is asked ---------------------------------------------------------------


def rest(method: str, path: str, body: str | None = None) -> Callable[[Surfaces], Refusal]:
    def send(s: Surfaces) -> Refusal:
        headers = {"Content-Type": "application/json"}
        answer = s.http.request(method, path, content=body, headers=headers)
        text = answer.text
        return Refusal(400 <= answer.status_code < 500 and "internal" not in text, text)

    return send


def mjpeg(query: str) -> Callable[[Surfaces], Refusal]:
    def send(s: Surfaces) -> Refusal:
        with s.http.stream("GET", f"/api/v1/sensors/camera/stream.mjpg{query}") as answer:
            status = answer.status_code
            text = answer.read().decode() if status != 200 else "a stream"
        return Refusal(400 <= status < 500, text)

    return send


def ws_rate(value: str) -> Callable[[Surfaces], Refusal]:
    def send(s: Surfaces) -> Refusal:
        with connect(f"{s.ws_url}?rate_hz={value}") as ws:
            first = json.loads(ws.recv(timeout=10))
        return Refusal(set(first) == {"error"}, json.dumps(first))

    return send


def ws_teleop_goal(number: str) -> Callable[[Surfaces], Refusal]:
    def send(s: Surfaces) -> Refusal:
        with connect(s.ws_url + "?rate_hz=0.2") as ws:
            ws.send(json.dumps({"type": "teleop.start", "motors": ["m1"]}))
            reply = _next_typed(ws, lambda m: m.get("type") == "teleop.started" or "error" in m)
            assert reply.get("type") == "teleop.started", reply
            goals = '{"type": "teleop.goals", "positions": {"m1": N}}'
            ws.send(goals.replace("N", number))
            error = _next_typed(ws, lambda m: "error" in m)
            ws.send(json.dumps({"type": "teleop.stop"}))  # the connection is still open
            _next_typed(ws, lambda m: m.get("type") == "teleop.stopped")
        return Refusal(True, json.dumps(error))

    return send


def _next_typed(ws: Any, wanted: Callable[[dict[str, Any]], bool]) -> dict[str, Any]:
    for _ in range(50):
        message = json.loads(ws.recv(timeout=10))
        if wanted(message):
            return dict(message)
    raise AssertionError("no such message")


def snap(path: str) -> Callable[[Surfaces], Refusal]:
    def send(s: Surfaces) -> Refusal:
        answer = s.snap.get(path)
        return Refusal(400 <= answer.status_code < 500, answer.text)

    return send


def zmq(request: dict[str, Any]) -> Callable[[Surfaces], Refusal]:
    def send(s: Surfaces) -> Refusal:
        answer = json.loads(s.zmq.reply_to(json.dumps(request).encode()))
        ok = isinstance(answer, dict) and "internal" not in answer.get("error", "internal")
        return Refusal(ok, json.dumps(answer))

    return send


def cli(*args: str) -> Callable[[Surfaces], Refusal]:
    def send(s: Surfaces) -> Refusal:
        result = run_poppy(*args, "--sim", "ideal", "--profile", "ergo-jr")
        lines = result.stderr.strip().splitlines()
        clear = (
            result.code != 0
            and len(lines) == 1
            and lines[0].startswith("error: ")
            and "unexpected" not in result.stderr
        )
        return Refusal(clear, result.stderr)

    return send


def zmq_property(prop: str, value: float) -> dict[str, Any]:
    return {
        "robot": {
            "set_primitive_property": {"primitive": "sinus", "property": prop, "value": value}
        }
    }


# -- the table -------------------------------------------------------------------------------


def goto(position: str, duration: str) -> str:
    return '{"positions": {"m1": P}, "duration_s": D}'.replace("P", position).replace("D", duration)


CASES: list[tuple[str, Callable[[Surfaces], Refusal], str]] = [
    # (case, how it is sent, what the refusal names)
    ("rest-gotos-duration-nan", rest("POST", "/api/v1/gotos", goto("10", "NaN")), "duration_s"),
    ("rest-gotos-position-inf", rest("POST", "/api/v1/gotos", goto("Infinity", "1")), "m1"),
    ("rest-gotos-position-1e309", rest("POST", "/api/v1/gotos", goto("1e309", "1")), "m1"),
    (
        "rest-solve-nan",
        rest("POST", "/api/v1/chains/chain/solve", '{"position": [NaN, 0, 0]}'),
        "position",
    ),
    (
        "rest-chain-goto-inf",
        rest(
            "POST", "/api/v1/chains/chain/goto", '{"position": [0.1, 0, 0.1], "duration": Infinity}'
        ),
        "duration",
    ),
    (
        "rest-forward-nan",
        rest("POST", "/api/v1/chains/chain/forward", '{"joints": {"m1": NaN}}'),
        "m1",
    ),
    ("rest-play-speed-nan", rest("POST", "/api/v1/moves/wave/play", '{"speed": NaN}'), "speed"),
    (
        "rest-compliant-nan",
        rest("PUT", "/api/v1/robot/compliant", '{"compliant": NaN}'),
        "compliant",
    ),
    ("rest-ik-xyz-400-digits", rest("POST", "/ik/chain/goto.json", IK_XYZ_HUGE), "xyz"),
    (
        "rest-ik-duration-400-digits",
        rest("POST", "/ik/chain/goto.json", IK_DURATION_HUGE),
        "duration",
    ),
    (
        "rest-v1-frequency-1e308",
        rest("PUT", "/api/v1/primitives/sinus/properties/frequency", '{"value": 1e308}'),
        "frequency",
    ),
    (
        "rest-pypot-update-freq-1e-300",
        rest("POST", "/primitives/sinus/properties/update_freq/value.json", "1e-300"),
        "update_freq",
    ),
    ("rest-mjpeg-fps-1e-300", mjpeg("?fps=1e-300"), "fps"),
    ("ws-rate-nan", ws_rate("nan"), "rate_hz"),
    ("ws-rate-0", ws_rate("0"), "rate_hz"),
    ("ws-rate-1e-300", ws_rate("1e-300"), "rate_hz"),
    ("ws-rate-abc", ws_rate("abc"), "rate_hz"),
    ("ws-teleop-goal-4000-digits", ws_teleop_goal(VERY_HUGE), "m1"),
    ("snap-frequency-1e308", snap("/primitive/sinus/set/frequency/1e308"), "frequency"),
    ("snap-update-freq-1e-300", snap("/primitive/sinus/set/update_freq/1e-300"), "update_freq"),
    ("zmq-update-freq-1e-300", zmq(zmq_property("update_freq", 1e-300)), "update_freq"),
    ("zmq-frequency-1e308", zmq(zmq_property("frequency", 1e308)), "frequency"),
    ("cli-goto-duration-1e-300", cli("robot", "goto", "m1=10", "--duration", "1e-300"), "duration"),
    (
        "cli-sinus-frequency-1e308",
        cli("primitive", "run", "sinus", "--set", "frequency=1e308", "--duration", "0.2"),
        "frequency",
    ),
    (
        "cli-sinus-update-freq-1e-300",
        cli("primitive", "run", "sinus", "--set", "update_freq=1e-300", "--duration", "0.2"),
        "update_freq",
    ),
]


@pytest.mark.parametrize(("send", "field"), [c[1:] for c in CASES], ids=[c[0] for c in CASES])
def test_a_hostile_number_is_refused_clearly(
    surfaces: Surfaces, send: Callable[[Surfaces], Refusal], field: str
) -> None:
    sinus = surfaces.robot.sinus
    before = (sinus.frequency, sinus.update_freq)
    refusal = send(surfaces)
    assert refusal.ok, refusal.text
    assert field in refusal.text
    assert "\n" not in refusal.text.strip()  # one line
    assert (sinus.frequency, sinus.update_freq) == before  # nothing was half-applied
