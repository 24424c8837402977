"""pypot's fast path answers as the routes do: numbers read and written as ``json`` does, the
goto without ``wait`` answered directly, and anything it cannot answer (a failure included)
left to the routes, behind the same guards."""

from __future__ import annotations

import json
from collections.abc import Iterator

import httpx
import pytest

from poppy_core.server.fastpath import plain_number, register_body
from poppy_core.server.pypot_json import pypot_bytes
from tests.helpers.server import Served
from tests.helpers.waiting import eventually

PYPOT_TYPE = "text/html; charset=UTF-8"


@pytest.mark.parametrize(
    "value",
    [0, -3, 2**53, 10.0, -0.0, 0.1, 1e16, 1.5e-7, 123.456, None, True, "a<b&c>", [1, 2.5]],
)
def test_a_register_answer_is_the_bytes_pypot_json_writes(value: object) -> None:
    assert register_body("goal_position", value) == pypot_bytes({"goal_position": value})


@pytest.mark.parametrize(
    "body",
    [b"10", b"-0", b"0", b"0.5", b"-12.75", b"1e2", b"1E-2", b"2.5e+3", b"123456789012345"],
)
def test_a_plain_number_is_read_as_json_reads_it(body: bytes) -> None:
    value = plain_number(body)
    expected = json.loads(body)
    assert value == expected
    assert type(value) is type(expected)


@pytest.mark.parametrize(
    "body", [b" 10", b"10 ", b"+1", b"01", b"1.", b".5", b"nan", b"1e9999", b'"10"', b"1" * 40]
)
def test_anything_else_goes_to_the_general_parser(body: bytes) -> None:
    assert plain_number(body) is None


@pytest.fixture
def client(served: Served) -> Iterator[httpx.Client]:
    with httpx.Client(base_url=served.url, timeout=10.0) as http:
        yield http


def test_a_goto_without_wait_is_answered_with_pypot_headers(
    client: httpx.Client, served: Served
) -> None:
    body = {"motors": ["m2"], "positions": ["12"], "duration": 0.2}
    answer = client.post("/motors/goto.json", json=body)
    assert answer.status_code == 202
    assert answer.content == b'{"motors":{"m2":12.0},"duration":0.2,"waiting":false}'
    assert answer.headers["content-type"] == PYPOT_TYPE
    assert answer.headers["x-content-type-options"] == "nosniff"
    assert answer.headers["cache-control"] == "no-store"
    eventually(lambda: abs(served.robot.motor("m2").goal_position - 12.0) < 0.5)


def test_a_refused_goto_gets_the_routes_error(client: httpx.Client) -> None:
    body = {"motors": ["m1", "m2"], "positions": [10], "duration": 1}
    answer = client.post("/motors/goto.json", json=body)
    assert answer.status_code == 400
    assert answer.json()["error"] == "not as many positions as motors"
    unknown = client.post("/motors/goto.json", json={**body, "motors": ["nope"]})
    assert unknown.status_code == 404


def test_a_failure_in_the_fast_path_is_the_routes_500(
    client: httpx.Client, served: Served, monkeypatch: pytest.MonkeyPatch
) -> None:
    service = served.app.state.service

    def broken(motor: str, register: str) -> object:
        raise RuntimeError("a bug")

    monkeypatch.setattr(service, "read", broken)
    answer = client.get("/motors/m1/registers/present_position/value.json")
    assert answer.status_code == 500
    assert answer.json()["error"].startswith("internal error (RuntimeError)")
    assert answer.headers["cache-control"] == "no-store"  # the guard's headers still


def test_values_become_plain_json_data() -> None:
    import numpy as np

    from poppy_core.server.values import jsonable

    assert jsonable(float("nan")) is None
    assert jsonable(float("-inf")) is None
    assert jsonable((1.5, float("inf"), (2, "a"))) == [1.5, None, [2, "a"]]
    assert jsonable({1: [np.float64(0.5)], "b": {"c": np.int64(3)}}) == {"1": [0.5], "b": {"c": 3}}
    assert jsonable(np.array([1.0, np.nan])) == [1.0, None]
    assert type(jsonable(np.float32(0.25))) is float


def test_the_motor_list_is_pypots(client: httpx.Client) -> None:
    answer = client.get("/motors/list.json")
    assert answer.status_code == 200
    assert answer.json() == {"motors": ["m1", "m2", "m3", "m4", "m5", "m6"]}
    assert answer.headers["content-type"] == PYPOT_TYPE
