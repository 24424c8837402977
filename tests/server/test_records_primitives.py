"""pypot's /records and /primitives routes: record, save, list, play, stop, delete; primitives."""

from __future__ import annotations

import os
import time
from pathlib import Path

import httpx
import pytest

from tests.helpers.server import Served


def test_record_save_list_play_stop_delete(
    client: httpx.Client, served: Served, moves_folder: str
) -> None:
    answer = client.post("/records/wave/record.json", json={"motors": "m1,m2"})
    assert answer.status_code == 202 and answer.json() == {"wave": "recording"}
    time.sleep(0.3)
    partial = client.get("/records/wave/value.json").json()
    assert partial["length"] > 0
    answer = client.post("/records/wave/save.json")
    assert answer.status_code == 202 and answer.json() == {"wave": "saved"}
    assert client.get("/records/list.json").json() == {"moves": ["wave"]}
    saved = [p.name for p in Path(moves_folder).iterdir()]
    assert saved == ["wave.move"]
    assert not Path(os.getcwd(), "wave.record").exists()

    value = client.get("/records/wave/value.json").json()
    frames = value["wave"]
    assert value["length"] == len(frames) > 5
    first = frames[min(frames, key=float)]
    assert set(first) == {"m1", "m2"} and len(first["m1"]) == 2

    answer = client.post("/records/wave/play.json", json={"speed": "-2.0"})
    assert answer.status_code == 202 and answer.json() == {"wave": "started replay"}
    answer = client.post("/records/wave/stop.json")
    assert answer.status_code == 202 and answer.json() == {"wave": "stopped"}
    answer = client.post("/records/wave/delete.json")
    assert answer.status_code == 202 and answer.json() == {"wave": "deleted"}
    assert client.get("/records/list.json").json() == {"moves": []}
    served.robot.compliant = True


@pytest.mark.parametrize(
    ("method", "path", "body", "status"),
    [
        ("POST", "/records/ghost/save.json", None, 404),
        ("POST", "/records/ghost/play.json", {"speed": 1}, 404),
        ("POST", "/records/ghost/play.json", {}, 400),
        ("POST", "/records/ghost/play.json", {"speed": "fast"}, 400),
        ("POST", "/records/ghost/stop.json", None, 400),
        ("POST", "/records/ghost/delete.json", None, 404),
        ("GET", "/records/ghost/value.json", None, 404),
        ("POST", "/records/ghost/record.json", {"motors": ["m9"]}, 404),
        ("POST", "/records/.bad/record.json", None, 400),
    ],
)
def test_record_errors(
    client: httpx.Client, method: str, path: str, body: object, status: int
) -> None:
    answer = client.request(method, path, json=body)
    assert answer.status_code == status
    assert set(answer.json()) == {"error", "tip", "details"}


def test_primitives_start_pause_resume_stop(client: httpx.Client, served: Served) -> None:
    assert "sinus" in client.get("/primitives/list.json").json()["primitives"]
    assert client.get("/primitives/running/list.json").json() == {"running_primitives": []}
    answer = client.get("/primitives/sinus/start.json")
    assert answer.status_code == 202 and answer.json() == {"sinus": "started"}
    assert client.get("/primitives/running/list.json").json() == {"running_primitives": ["sinus"]}
    assert client.get("/primitives/sinus/pause.json").json() == {"sinus": "paused"}
    assert served.robot.sinus.state == "paused"
    assert client.get("/primitives/sinus/resume.json").json() == {"sinus": "resumed"}
    assert served.robot.sinus.state == "running"
    answer = client.get("/primitives/sinus/stop.json")
    assert answer.status_code == 202 and answer.json() == {"sinus": "stopped"}
    assert client.get("/primitives/running/list.json").json() == {"running_primitives": []}
    assert client.get("/primitives/nope/start.json").status_code == 404


def test_primitive_properties_and_methods(client: httpx.Client, served: Served) -> None:
    props = client.get("/primitives/sinus/properties/list.json").json()["property"]
    assert "amplitude" in props
    answer = client.post("/primitives/sinus/properties/amplitude/value.json", content="12.5")
    assert answer.status_code == 204 and answer.content == b""
    assert client.get("/primitives/sinus/properties/amplitude/value.json").json() == {
        "sinus.amplitude": 12.5
    }
    bad = client.post("/primitives/sinus/properties/amplitude/value.json", content='"loud"')
    assert bad.status_code == 400
    assert client.get("/primitives/sinus/properties/nope/value.json").status_code == 404
    methods = client.get("/primitives/sinus/methods/list.json").json()["methods"]
    assert "start" in methods
    answer = client.post("/primitives/sinus/methods/start/args.json", json={})
    assert answer.status_code == 200 and answer.json() == {"sinus:start": None}
    assert served.robot.sinus.is_alive()
    client.post("/primitives/sinus/methods/stop/args.json", json={})
    assert not served.robot.sinus.is_alive()
    assert client.post("/primitives/sinus/methods/nope/args.json", json={}).status_code == 404
    assert client.post("/primitives/sinus/methods/stop/args.json", json={"x": 1}).status_code == 400
