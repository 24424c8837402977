"""Token enforcement, body size limit, CORS origins (the Host/Origin rules: test_origins.py)."""

from __future__ import annotations

from collections.abc import Iterator

import httpx
import pytest
from websockets.exceptions import InvalidStatus
from websockets.sync.client import connect

from poppy_core.server import OriginPolicy
from tests.helpers.server import Served, serve
from tests.helpers.waiting import http_timeout

TOKEN = "s3cret-token"


@pytest.fixture(scope="module")
def guarded(moves_folder: str) -> Iterator[Served]:
    """An Ergo Jr served with a token and one allowed origin."""
    yield from serve(moves_folder, token=TOKEN, policy=OriginPolicy(["http://app.local"]))


@pytest.mark.parametrize(
    ("method", "path"),
    [
        ("GET", "/robot.json"),
        ("GET", "/motors/list.json"),
        ("POST", "/motors/m1/registers/led/value.json"),
        ("GET", "/api/v1/robot"),
        ("PUT", "/api/v1/motors/m1/registers/led"),
        ("GET", "/openapi.json"),
        ("GET", "/docs"),
        ("GET", "/primitives/sinus/start.json"),
    ],
)
def test_every_route_needs_the_token(guarded: Served, method: str, path: str) -> None:
    with httpx.Client(base_url=guarded.url, timeout=http_timeout()) as http:
        refused = http.request(method, path, content=b"true")
        assert refused.status_code == 401
        assert refused.headers["www-authenticate"] == "Bearer"
        wrong = http.request(
            method, path, content=b"true", headers={"Authorization": "Bearer nope"}
        )
        assert wrong.status_code == 401
    assert not guarded.robot.sinus.is_alive()


def test_token_in_header_or_query(guarded: Served) -> None:
    with httpx.Client(base_url=guarded.url, timeout=http_timeout()) as http:
        header = {"Authorization": f"Bearer {TOKEN}"}
        assert http.get("/motors/list.json", headers=header).status_code == 200
        assert http.get(f"/motors/list.json?token={TOKEN}").status_code == 200
        assert http.get("/api/v1/robot", headers=header).status_code == 200


def test_websocket_needs_the_token(guarded: Served) -> None:
    base = guarded.url.replace("http://", "ws://") + "/api/v1/ws"
    with pytest.raises(InvalidStatus), connect(base):
        pass
    with connect(f"{base}?token={TOKEN}") as ws:
        assert "m1" in ws.recv(timeout=2)


def test_websocket_token_as_a_subprotocol(guarded: Served) -> None:
    """What the home page sends: ``poppy-token.<hex>``, echoed back, the URL left clean."""
    from websockets.typing import Subprotocol

    base = guarded.url.replace("http://", "ws://") + "/api/v1/ws"
    offered = Subprotocol("poppy-token." + TOKEN.encode().hex())
    with connect(base, subprotocols=[offered]) as ws:
        assert ws.subprotocol == offered
        assert "m1" in ws.recv(timeout=2)
    wrong = Subprotocol("poppy-token." + b"nope".hex())
    for bad in (wrong, Subprotocol("poppy-token.zz")):
        with pytest.raises(InvalidStatus), connect(base, subprotocols=[bad]):
            pass


def test_cors_only_for_the_allowed_origin(guarded: Served) -> None:
    with httpx.Client(base_url=guarded.url, timeout=http_timeout()) as http:
        allowed = http.options("/robot.json", headers={"Origin": "http://app.local"})
        assert allowed.status_code == 204
        assert allowed.headers["access-control-allow-origin"] == "http://app.local"
        other = http.options("/robot.json", headers={"Origin": "http://evil.example"})
        assert other.status_code == 403
        assert "access-control-allow-origin" not in other.headers
        # an allowed page reads the 401 of a request without the token (CORS headers on it)
        refused = http.get("/robot.json", headers={"Origin": "http://app.local"})
        assert refused.status_code == 401
        assert refused.headers["access-control-allow-origin"] == "http://app.local"


def test_large_bodies_are_refused(client: httpx.Client) -> None:
    big = b"[" + b"1," * 40_000 + b"1]"
    answer = client.post("/motors/m1/registers/pid/value.json", content=big)
    assert answer.status_code == 413

    def chunks() -> Iterator[bytes]:
        for _ in range(100):
            yield b" " * 1024

    streamed = client.post("/api/v1/gotos", content=chunks())
    assert streamed.status_code == 413


def test_errors_never_500(client: httpx.Client) -> None:
    probes = [
        ("PUT", "/api/v1/motors/m1/registers/goal_position", b'{"value": NaN}'),
        ("PUT", "/api/v1/motors/m1/registers/goal_position", b'{"value": "x"}'),
        ("PUT", "/api/v1/motors/m1/registers/present_load", b'{"value": 1}'),
        ("PUT", "/api/v1/motors/m1/registers/led", b'{"value": {"a": 1}}'),
        ("PATCH", "/api/v1/motors", b'{"m1": {"goal_position": 1e300}}'),
        ("POST", "/api/v1/gotos", b'{"positions": {"m1": NaN}, "duration_s": 1}'),
        ("POST", "/api/v1/gotos", b'{"positions": {"m1": 1}, "duration_s": -1}'),
        ("POST", "/motors/goto.json", b'{"motors": [1], "positions": [1e999], "duration": 1}'),
        ("POST", "/primitives/sinus/properties/amplitude/value.json", b"NaN"),
        ("POST", "/records/x/play.json", b"[]"),
        ("POST", "/records/x/record.json", b'{"motors": 5}'),
    ]
    for method, path, body in probes:
        answer = client.request(method, path, content=body)
        assert 400 <= answer.status_code < 500, (path, body, answer.text)


def test_docs_pass_the_token_to_the_schema(guarded: Served) -> None:
    with httpx.Client(base_url=guarded.url, timeout=http_timeout()) as http:
        page = http.get(f"/docs?token={TOKEN}")
        assert page.status_code == 200
        assert f"/openapi.json?token={TOKEN}" in page.text
        assert http.get(f"/openapi.json?token={TOKEN}").json()["info"]["title"]
