"""Refusals and departures that are no error: a refused WebSocket handshake, a client leaving
right after ``teleop.stop``; and a token of any characters, compared as the bytes it came in."""

from __future__ import annotations

import json
import logging
import time
from collections.abc import Iterator

import httpx
import pytest
from websockets.exceptions import InvalidStatus
from websockets.sync.client import connect

from poppy_core import from_profile
from poppy_core.robot import Robot
from poppy_core.server import ServerThread, create_app
from tests.helpers.waiting import http_timeout

TOKEN = "pässwörd-ключ-🤖"


class Recorder(logging.Handler):
    """Keeps the records of ERROR and above."""

    def __init__(self) -> None:
        super().__init__(logging.ERROR)
        self.records: list[logging.LogRecord] = []

    def emit(self, record: logging.LogRecord) -> None:
        self.records.append(record)


@pytest.fixture(scope="module")
def robot(moves_folder: str) -> Iterator[Robot]:
    robot = from_profile("ergo-jr", sim=True)
    yield robot
    robot.close()


@pytest.fixture
def errors() -> Iterator[Recorder]:
    """ERROR records of uvicorn (which does not propagate to the root) and of poppy."""
    recorder = Recorder()
    loggers = [logging.getLogger("uvicorn"), logging.getLogger("poppy_core")]
    for logger in loggers:
        logger.addHandler(recorder)
    yield recorder
    for logger in loggers:
        logger.removeHandler(recorder)


@pytest.fixture(scope="module")
def with_token(robot: Robot) -> Iterator[ServerThread]:
    server = ServerThread(create_app(robot, token=TOKEN)).start()
    yield server
    server.stop()


def _ws(server: ServerThread, query: str = "") -> str:
    return server.url.replace("http://", "ws://") + "/api/v1/ws" + query


def test_a_refused_websocket_handshake_is_answered_and_logs_no_error(
    with_token: ServerThread, errors: Recorder
) -> None:
    for headers, status in (({}, 401), ({"Origin": "http://evil.example"}, 403)):
        with (
            pytest.raises(InvalidStatus) as refused,
            connect(_ws(with_token), additional_headers=headers, open_timeout=10),
        ):
            pass
        assert refused.value.response.status_code == status
        assert b'"error"' in refused.value.response.body
    # the error would be logged as the app returns, just after the answer: give it the time
    with httpx.Client(base_url=with_token.url, timeout=http_timeout()) as http:
        assert http.get("/robot.json", params={"token": TOKEN}).status_code == 200
    time.sleep(1.0)  # nothing is logged in that time (the error came at once)
    assert not errors.records, errors.records[0].getMessage()


def test_a_client_leaving_right_after_teleop_stop_logs_no_error(
    with_token: ServerThread, errors: Recorder
) -> None:
    url = _ws(with_token, "?rate_hz=1&" + str(httpx.QueryParams({"token": TOKEN})))
    for _ in range(5):
        with connect(url, open_timeout=10) as ws:
            ws.send(json.dumps({"type": "teleop.start", "motors": ["m1"]}))
            while "teleop.started" not in str(ws.recv(timeout=10)):
                pass
            ws.send(json.dumps({"type": "teleop.stop"}))
        # closed at once: the server's teleop.stopped answer finds the connection closing
    time.sleep(1.0)  # nothing is logged in that time (the error came at once)
    assert not errors.records, errors.records[0].getMessage()


def test_a_non_ascii_token_matches_however_it_is_carried(with_token: ServerThread) -> None:
    with httpx.Client(base_url=with_token.url, timeout=http_timeout()) as http:
        bearer = b"Bearer " + TOKEN.encode()
        assert http.get("/robot.json", headers={"Authorization": bearer}).status_code == 200
        assert http.get("/robot.json", params={"token": TOKEN}).status_code == 200
        wrong = b"Bearer " + TOKEN.encode()[:-1] + b"!"
        assert http.get("/robot.json", headers={"Authorization": wrong}).status_code == 401
        latin = b"Bearer " + TOKEN.encode("utf-8").decode("latin-1").encode("utf-8")
        assert http.get("/robot.json", headers={"Authorization": latin}).status_code == 401
    protocol = "poppy-token." + TOKEN.encode().hex()
    with connect(_ws(with_token), subprotocols=[protocol], open_timeout=10) as ws:  # type: ignore[list-item]
        assert "m1" in json.loads(ws.recv(timeout=10))
