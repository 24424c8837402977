"""pypot's routes answer as pypot did: JSON typed ``text/html; charset=UTF-8``, uncached, and the
running list names a recorded or played move ``_<move>_recorder`` / ``_<move>_player``.

pypot 5.0.2's server (``pypot/server/httpserver.py``) wrote JSON strings through Tornado, whose
default type is ``text/html; charset=UTF-8``; pages written for it (puppet-master's move
recorder, poppy-monitor) parse what jQuery or XHR hand them with ``JSON.parse``. The routes below
are every pypot route those two pages call, with the bodies they send.
"""

from __future__ import annotations

import json
from typing import Any

import httpx
import pytest

from tests.helpers.server import Served
from tests.helpers.waiting import eventually

PYPOT_TYPE = "text/html; charset=UTF-8"
FORM = {"Content-Type": "application/x-www-form-urlencoded; charset=UTF-8"}  # jQuery's $.post
XHR_JSON = {"Content-Type": "application/json; charset=UTF-8"}  # poppy-monitor's postJSON


def pypot_answer(answer: httpx.Response, status: int) -> Any:
    """The JSON of ``answer`` after checking it carries pypot's status, type and headers."""
    assert answer.status_code == status, answer.text
    assert answer.headers["content-type"] == PYPOT_TYPE
    assert answer.headers["cache-control"] == "no-store"
    return json.loads(answer.text)


# (method, path, body, headers, status, expected JSON or a check of it)
PAGE_CALLS: list[tuple[str, str, str | None, dict[str, str], int, Any]] = [
    # puppet-master, templates/EN/move-recorder.html
    ("GET", "/motors/aliases/list.json", None, {}, 200, {"aliases": ["base", "tip"]}),
    ("GET", "/motors/base/list.json", None, {}, 200, {"base": ["m1", "m2", "m3"]}),
    ("POST", "/motors/m1/registers/compliant/value.json", "false", FORM, 202, {"compliant": False}),
    ("POST", "/motors/m1/registers/compliant/value.json", "true", FORM, 202, {"compliant": True}),
    ("GET", "/records/list.json", None, {}, 200, lambda body: isinstance(body["moves"], list)),
    (
        "GET",
        "/primitives/running/list.json",
        None,
        {},
        200,
        lambda body: isinstance(body["running_primitives"], list),
    ),
    # poppy-monitor, js/poppy-object.js (the old spellings, rewritten to the routes)
    (
        "GET",
        "/robot.json",
        None,
        {},
        200,
        lambda body: body["motors"][0]["name"] == "m1" and body["primitives"],
    ),
    ("POST", "/motor/m2/register/compliant/value.json", "true", XHR_JSON, 202, {"compliant": True}),
    ("POST", "/motor/m2/register/led/value.json", '"green"', XHR_JSON, 202, {"led": "green"}),
    ("POST", "/primitive/sinus/property/amplitude/value.json", "10", XHR_JSON, 204, None),
    ("POST", "/primitive/sinus/method/stop/args.json", "{}", XHR_JSON, 200, {"sinus:stop": None}),
]


@pytest.mark.parametrize(
    ("method", "path", "body", "headers", "status", "expected"),
    PAGE_CALLS,
    ids=[f"{call[0]} {call[1]}" for call in PAGE_CALLS],
)
def test_the_routes_pages_call_answer_as_pypot_did(
    client: httpx.Client,
    method: str,
    path: str,
    body: str | None,
    headers: dict[str, str],
    status: int,
    expected: Any,
) -> None:
    answer = client.request(method, path, content=body, headers=headers)
    if status == 204:
        assert answer.status_code == 204 and answer.content == b""
        return
    data = pypot_answer(answer, status)
    if callable(expected):
        assert expected(data), data
    else:
        assert data == expected


def test_register_reads_of_the_fast_path_and_its_fallback_answer_the_same(
    client: httpx.Client,
) -> None:
    fast = pypot_answer(client.get("/motors/m1/registers/present_position/value.json"), 200)
    assert isinstance(fast["present_position"], float)
    refused = client.post("/motors/m1/registers/goal_position/value.json", content="not json")
    assert set(pypot_answer(refused, 400)) == {"error", "tip", "details"}


def test_errors_of_pypot_routes_are_pypot_typed_and_never_markup(client: httpx.Client) -> None:
    answer = client.get("/motors/%3Cimg%20src%3Dx%20onerror%3Dalert(1)%3E/registers/list.json")
    body = pypot_answer(answer, 404)
    assert "<img" in body["error"]  # the name is quoted back, as JSON...
    assert "<" not in answer.text and ">" not in answer.text  # ...but never as markup
    assert "default-src 'none'" in answer.headers["content-security-policy"]
    assert answer.headers["x-content-type-options"] == "nosniff"


def test_the_v1_api_stays_json(client: httpx.Client) -> None:
    for path in ("/api/v1/motors", "/api/v1/nope"):
        answer = client.get(path)
        assert answer.headers["content-type"] == "application/json", path


def test_a_played_move_is_listed_as_pypot_named_its_player(
    client: httpx.Client, served: Served
) -> None:
    def running() -> list[str]:
        listed = pypot_answer(client.get("/primitives/running/list.json"), 200)
        names = listed["running_primitives"]
        assert isinstance(names, list)
        return names

    recorded = client.post(
        "/records/pm_take/record.json", content='{"motors": "m1,m2"}', headers=FORM
    )
    assert pypot_answer(recorded, 202) == {"pm_take": "recording"}
    assert "_pm_take_recorder" in running()
    assert eventually(lambda: client.get("/records/pm_take/value.json").json()["length"] > 50)
    saved = client.post("/records/pm_take/save.json", content="{}", headers=FORM)
    assert pypot_answer(saved, 202) == {"pm_take": "saved"}
    assert "_pm_take_recorder" not in running()
    assert "pm_take" in pypot_answer(client.get("/records/list.json"), 200)["moves"]

    played = client.post("/records/pm_take/play.json", content='{"speed": "0.1"}', headers=FORM)
    assert pypot_answer(played, 202) == {"pm_take": "started replay"}
    assert "_pm_take_player" in running()
    stopped = client.post("/records/pm_take/stop.json", content="{}", headers=FORM)
    assert pypot_answer(stopped, 202) == {"pm_take": "stopped"}
    assert eventually(lambda: "_pm_take_player" not in running())
    client.post("/records/pm_take/delete.json")
