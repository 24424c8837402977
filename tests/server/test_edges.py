"""Numbers and documents at the edges: each is a 4xx with one line, or a WebSocket error message.

Huge integers (``json`` refuses more than 4,300 digits; 400 digits overflow a float), nesting
deeper than the interpreter's recursion limit, durations that vanish, and primitive failures
(their traceback stays in the server's log).
"""

from __future__ import annotations

import json
import time

import httpx
import pytest
from websockets.exceptions import ConnectionClosedError
from websockets.sync.client import connect

from poppy_core.motion import Primitive, attach_primitive
from tests.helpers.server import Served

DIGITS_5000 = "1" + "0" * 5000
DIGITS_400 = "1" + "0" * 400
DEEP = "[" * 30_000 + "]" * 30_000
DEEP_OBJECT = '{"":' * 10_000 + "1" + "}" * 10_000  # under the 64 KiB limits
VALUES = {"5000 digits": DIGITS_5000, "400 digits": DIGITS_400, "-400 digits": "-" + DIGITS_400}
DOCUMENTS = {"30k-deep array": DEEP, "10k-deep object": DEEP_OBJECT}


def _one_line_4xx(answer: httpx.Response) -> dict[str, str]:
    assert 400 <= answer.status_code < 500, (answer.status_code, answer.text[:300])
    body = answer.json()
    text = body.get("error", body.get("detail"))
    if isinstance(text, list):  # v1's pydantic validation errors keep FastAPI's list form
        return dict(body)
    assert isinstance(text, str) and "\n" not in text and len(text) <= 300, text
    if "error" in body:
        assert set(body) >= {"error", "tip", "details"}
    return dict(body)


PYPOT_BODIES = [
    ("/motors/m1/registers/goal_position/value.json", "{}"),  # the fast path first
    ("/motors/m1/registers/led/value.json", "{}"),
    ("/motors/m1/goto.json", '{{"position": {}, "duration": 1}}'),
    ("/motors/m1/goto.json", '{{"position": 10, "duration": {}}}'),
    ("/motors/goto.json", '{{"motors": ["m1"], "positions": [{}], "duration": 1}}'),
    ("/records/edge/play.json", '{{"speed": {}}}'),
    ("/records/edge/record.json", '{{"motors": {}}}'),
    ("/primitives/sinus/properties/amplitude/value.json", "{}"),
    ("/primitives/sinus/methods/start/args.json", "{}"),
]


@pytest.mark.parametrize(
    "value", [*VALUES.values(), *DOCUMENTS.values()], ids=[*VALUES, *DOCUMENTS]
)
@pytest.mark.parametrize(("path", "template"), PYPOT_BODIES, ids=[p for p, _ in PYPOT_BODIES])
def test_pypot_routes_refuse_huge_numbers_and_deep_documents(
    client: httpx.Client, path: str, template: str, value: str
) -> None:
    body = template.format(value).encode()
    _one_line_4xx(client.post(path, content=body))
    if value is DIGITS_5000:
        answer = client.post(path, content=body).json()
        assert "too many digits" in answer["error"]


@pytest.mark.parametrize("value", [DIGITS_5000, DIGITS_400, DEEP], ids=["5000", "400", "deep"])
@pytest.mark.parametrize(
    ("method", "path", "template"),
    [
        ("PUT", "/api/v1/motors/m1/registers/goal_position", '{{"value": {}}}'),
        ("PATCH", "/api/v1/motors", '{{"m1": {{"goal_position": {}}}}}'),
        ("POST", "/api/v1/gotos", '{{"positions": {{"m1": {}}}, "duration_s": 1}}'),
        ("PUT", "/api/v1/primitives/sinus/properties/amplitude", '{{"value": {}}}'),
        ("POST", "/api/v1/primitives/sinus/methods/start", '{{"args": [{}]}}'),
    ],
)
def test_v1_routes_refuse_huge_numbers_and_deep_documents(
    client: httpx.Client, method: str, path: str, template: str, value: str
) -> None:
    headers = {"Content-Type": "application/json"}
    _one_line_4xx(client.request(method, path, content=template.format(value), headers=headers))


@pytest.mark.parametrize("duration", ["1e-100", "1e-300", "5e-324", "0.0000001"])
def test_vanishing_goto_durations_are_refused(
    client: httpx.Client, served: Served, duration: str
) -> None:
    headers = {"Content-Type": "application/json"}
    v1 = f'{{"positions": {{"m1": 10}}, "duration_s": {duration}}}'
    assert client.post("/api/v1/gotos", content=v1, headers=headers).status_code == 422
    pypot = f'{{"position": 10, "duration": {duration}}}'
    error = _one_line_4xx(client.post("/motors/m1/goto.json", content=pypot))
    assert "duration must be 0 (at once) or at least 0.001 s" in error["error"]  # the library's
    several = f'{{"motors": ["m1"], "positions": [10], "duration": {duration}}}'
    _one_line_4xx(client.post("/motors/goto.json", content=several))


def test_the_shortest_goto_runs(client: httpx.Client, served: Served) -> None:
    body = {"position": 0, "duration": 0.001, "wait": True}
    assert client.post("/motors/m2/goto.json", json=body).status_code == 202


WS_MESSAGES = {
    "5000 digits": '{"m1": {"goal_position": ' + DIGITS_5000 + "}}",
    "400 digits": '{"m1": {"goal_position": ' + DIGITS_400 + "}}",
    "400-digit led": '{"m1": {"led": ' + DIGITS_400 + "}}",
    **DOCUMENTS,
    "not json": "not json",
    "not an object": '{"m1": 5}',
    "a list": "[]",
}


@pytest.mark.parametrize("message", list(WS_MESSAGES.values()), ids=list(WS_MESSAGES))
def test_websocket_messages_get_an_error_and_the_stream_goes_on(
    served: Served, message: str
) -> None:
    url = served.url.replace("http://", "ws://") + "/api/v1/ws"
    with connect(url) as ws:
        ws.recv(timeout=5)
        ws.send(message)
        errors = []
        deadline = time.monotonic() + 10
        while not errors and time.monotonic() < deadline:
            frame = json.loads(ws.recv(timeout=5))
            if "error" in frame:
                errors.append(frame["error"])
        assert errors and "\n" not in errors[0] and len(errors[0]) <= 300
        assert "m1" in json.loads(ws.recv(timeout=5))  # still streaming


def test_websocket_invalid_utf8_and_oversize_messages(served: Served) -> None:
    url = served.url.replace("http://", "ws://") + "/api/v1/ws"
    with connect(url) as ws:
        ws.send(b"\xff\xfe{")
        while "error" not in (frame := json.loads(ws.recv(timeout=5))):
            pass
        assert "JSON syntax error" in frame["error"]
    with connect(url, max_size=None) as ws:
        ws.send("[" + "1," * 40_000 + "1]")  # above the 64 KiB message limit
        with pytest.raises(ConnectionClosedError) as closed:
            for _ in range(100):
                ws.recv(timeout=5)
        assert closed.value.rcvd is not None and closed.value.rcvd.code == 1009


class Boom(Primitive):
    """A primitive whose code fails."""

    def run(self) -> None:
        raise RuntimeError("boom at the edge")


def test_primitive_failures_carry_no_traceback(client: httpx.Client, served: Served) -> None:
    attach_primitive(served.robot, "boom", Boom(served.robot))
    assert client.post("/api/v1/primitives/boom/start").status_code == 200
    deadline = time.monotonic() + 10
    while (info := client.get("/api/v1/primitives/boom").json())["state"] != "failed":
        assert time.monotonic() < deadline
        time.sleep(0.05)
    assert info["error"] == {"type": "RuntimeError", "message": "boom at the edge"}
    for answer in (client.get("/api/v1/primitives"), client.get("/robot.json")):
        assert "Traceback" not in answer.text and ".py" not in answer.text
    assert "Traceback" in served.robot.boom.error.traceback  # kept for the server's log
