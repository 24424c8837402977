"""The v1 API: robot, motors, registers, groups, gotos, primitives, moves, OpenAPI."""

from __future__ import annotations

import time

import httpx
import numpy as np

from tests.helpers.robots import reached
from tests.helpers.server import Served
from tests.helpers.waiting import eventually


def test_openapi_documents_v1(client: httpx.Client) -> None:
    schema = client.get("/openapi.json").json()
    for path in ("/api/v1/robot", "/api/v1/motors/{motor}/registers/{register}", "/api/v1/gotos"):
        assert path in schema["paths"]
    assert "GotoRequest" in schema["components"]["schemas"]
    assert client.get("/docs").status_code == 200


def test_robot_and_groups(client: httpx.Client) -> None:
    robot = client.get("/api/v1/robot").json()
    assert robot["motors"] == ["m1", "m2", "m3", "m4", "m5", "m6"]
    assert robot["groups"] == {"base": ["m1", "m2", "m3"], "tip": ["m4", "m5", "m6"]}
    assert client.get("/api/v1/groups/tip").json() == ["m4", "m5", "m6"]
    assert client.get("/api/v1/groups/nope").status_code == 404
    state = client.get("/api/v1/robot/state").json()
    assert set(state["m1"]) >= {"present_position", "present_speed", "led"}
    assert (
        client.put("/api/v1/robot/compliant", json={"compliant": False}).json()["compliant"]
        is False
    )
    assert client.put("/api/v1/robot/compliant", json={"compliant": True}).json()["compliant"]


def test_motor_registers(client: httpx.Client, served: Served) -> None:
    motor = client.get("/api/v1/motors/m1").json()
    assert motor["id"] == 1 and motor["model"] == "XL-320" and motor["online"] is True
    assert client.get("/api/v1/motors/m1/registers/led").json() == {
        "motor": "m1",
        "register": "led",
        "value": "off",
    }
    answer = client.put("/api/v1/motors/m1/registers/led", json={"value": "green"})
    assert answer.status_code == 200 and answer.json()["value"] == "green"
    assert served.robot.m1.led == "green"
    served.robot.m1.compliant = False  # a compliant motor's goal is refused (409)
    answer = client.put("/api/v1/motors/m1/registers/goal_position", json={"value": 500})
    # Beyond the angle limits: clamped to them, as the library does, and the answer says so.
    assert answer.status_code == 200
    assert answer.json()["value"] == served.robot.m1.angle_limit[1]
    served.robot.m1.compliant = True
    assert client.get("/api/v1/motors/m7/registers/led").status_code == 404
    assert client.get("/api/v1/registers/id").json() == {f"m{i}": i for i in range(1, 7)}
    served.robot.m1.led = "off"


def test_patch_is_all_or_nothing(client: httpx.Client, served: Served) -> None:
    answer = client.patch("/api/v1/motors", json={"m5": {"led": "red"}, "m6": {"led": "nope"}})
    assert answer.status_code == 422
    assert served.robot.m5.led == "off"
    answer = client.patch("/api/v1/motors", json={"m5": {"led": "red", "torque_limit": 50}})
    assert answer.status_code == 200
    assert answer.json() == {"m5": {"led": "red", "torque_limit": 50}}
    assert served.robot.m5.led == "red" and served.robot.m5.torque_limit == 50
    served.robot.m5.led = "off"
    served.robot.m5.torque_limit = 100


def test_goto_matches_the_robot(client: httpx.Client, served: Served) -> None:
    served.robot.compliant = False
    body = {"positions": {"m1": 15, "m3": -20}, "duration_s": 0.4, "wait": True}
    answer = client.post("/api/v1/gotos", json=body)
    assert answer.status_code == 200
    assert answer.json() == {
        "positions": {"m1": 15.0, "m3": -20.0},
        "duration_s": 0.4,
        "control": "minjerk",
        "waited": True,
        "done": True,
    }
    assert eventually(lambda: reached(served.robot, {"m1": 15, "m3": -20}, 2.0))
    served.robot.compliant = True
    assert client.post("/api/v1/gotos", json={"positions": {}, "duration_s": 1}).status_code == 422


def test_primitives(client: httpx.Client) -> None:
    listed = client.get("/api/v1/primitives").json()
    assert "sinus" in [p["name"] for p in listed]
    started = client.post("/api/v1/primitives/square/start").json()
    assert started["state"] == "running" and started["class"] == "Square"
    stopped = client.post("/api/v1/primitives/square/stop").json()
    assert stopped["state"] == "stopped" and stopped["alive"] is False
    answer = client.put("/api/v1/primitives/square/properties/amplitude", json={"value": 5})
    assert answer.status_code == 200 and answer.json()["properties"]["amplitude"] == 5
    answer = client.post("/api/v1/primitives/square/methods/nope", json={})
    assert answer.status_code == 404


def test_moves(client: httpx.Client) -> None:
    assert client.post("/api/v1/moves/v1move/record", json={"motors": ["tip"]}).status_code == 202
    assert client.get("/api/v1/moves/status").json()["recording"] == ["v1move"]
    time.sleep(0.3)
    saved = client.post("/api/v1/moves/v1move/save").json()
    assert saved["motors"] == ["m4", "m5", "m6"] and saved["frames"] > 5
    assert "v1move" in [m["name"] for m in client.get("/api/v1/moves").json()]
    move = client.get("/api/v1/moves/v1move?positions=true").json()
    assert len(move["positions"]) == move["frames"]
    assert client.post("/api/v1/moves/v1move/play", json={"speed": 4}).status_code == 202
    assert client.post("/api/v1/moves/v1move/stop").status_code == 200
    assert client.post("/api/v1/moves/ghost/save").status_code == 409
    assert client.post("/api/v1/moves/ghost/stop").status_code == 409
    assert client.delete("/api/v1/moves/v1move").status_code == 204
    assert client.delete("/api/v1/moves/v1move").status_code == 404


def test_one_rule_for_move_names_everywhere(client: httpx.Client, moves_folder: str) -> None:
    """A name the CLI and the library accept ("my wave.v2") is one REST plays (it was 422);
    a file no name can reach is not listed."""
    from pathlib import Path

    from poppy_core.motion import Move, save_move

    save_move(Move(10, ["m1"], [[0.0], [1.0]]), "my wave.v2")
    (Path(moves_folder) / "wave (copy).move").write_bytes(b"{}")
    listed = [m["name"] for m in client.get("/api/v1/moves").json()]
    assert "my wave.v2" in listed and "wave (copy)" not in listed
    assert client.get("/api/v1/moves/my wave.v2").status_code == 200
    assert client.post("/api/v1/moves/my wave.v2/play", json={"speed": 4}).status_code == 202
    assert client.post("/api/v1/moves/my wave.v2/stop").status_code == 200
    assert "my wave.v2" in client.get("/records/list.json").json()["moves"]
    refused = client.get("/api/v1/moves/.hidden")
    assert refused.status_code == 422 and "not a move name" in refused.text
    assert client.delete("/api/v1/moves/my wave.v2").status_code == 204


def test_the_move_list_gives_each_duration(client: httpx.Client, moves_folder: str) -> None:
    """As `poppy moves list` does: seconds and frames, null for a file that is not a move."""
    from pathlib import Path

    from poppy_core.motion import Move, save_move

    save_move(Move(20, ["m1"], np.zeros((41, 1))), "two_seconds")
    (Path(moves_folder) / "broken.move").write_bytes(b"not a move")
    try:
        listed = {m["name"]: m for m in client.get("/api/v1/moves").json()}
        assert listed["two_seconds"]["duration_s"] == 2.0
        assert listed["two_seconds"]["frames"] == 41
        assert listed["broken"]["duration_s"] is None and listed["broken"]["frames"] is None
        save_move(Move(20, ["m1"], np.zeros((21, 1))), "two_seconds")  # replaced: read again
        listed = {m["name"]: m for m in client.get("/api/v1/moves").json()}
        assert listed["two_seconds"]["duration_s"] == 1.0
    finally:
        for name in ("two_seconds.move", "broken.move"):
            (Path(moves_folder) / name).unlink()
