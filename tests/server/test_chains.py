"""Kinematic chains over HTTP: pypot's /ik routes (its answer shapes) and the v1 /chains API."""

from __future__ import annotations

import time
from collections.abc import Iterator

import httpx
import numpy as np
import pytest

from poppy_core import from_profile
from poppy_core.robot import Robot
from poppy_core.server import ServerThread, create_app
from tests.helpers.waiting import http_timeout


@pytest.fixture(scope="module")
def ergo(moves_folder: str) -> Iterator[tuple[str, Robot]]:
    """A virtual Ergo Jr with its creature (so ``robot.chain``), served on 127.0.0.1."""
    robot = from_profile("ergo-jr", sim=True)
    robot.compliant = False
    server = ServerThread(create_app(robot)).start()
    try:
        yield server.url, robot
    finally:
        server.stop()
        robot.close()


@pytest.fixture
def http(ergo: tuple[str, Robot]) -> Iterator[httpx.Client]:
    with httpx.Client(base_url=ergo[0], timeout=http_timeout(20.0)) as client:
        yield client


def _floats(text: str) -> list[float]:
    return [float(v) for v in text.split(",")]


def test_pypot_value_shape(http: httpx.Client, ergo: tuple[str, Robot]) -> None:
    answer = http.get("/ik/chain/value.json")
    assert answer.status_code == 200
    body = answer.json()
    assert set(body) == {"xyz", "rot"}
    assert isinstance(body["xyz"], str) and len(_floats(body["xyz"])) == 3
    assert _floats(body["xyz"]) == pytest.approx(ergo[1].chain.position, abs=1e-3)
    assert _floats(body["rot"]) == pytest.approx(ergo[1].chain.orientation, abs=1e-3)


def test_pypot_unknown_chain_is_404(http: httpx.Client) -> None:
    answer = http.get("/ik/l_arm_chain/value.json")
    assert answer.status_code == 404
    body = answer.json()
    assert set(body) == {"error", "tip", "details"}
    assert "Chain 'l_arm_chain' does not exist" in body["error"]


def test_pypot_goto_moves_and_answers_the_pose(http: httpx.Client, ergo: tuple[str, Robot]) -> None:
    target = [0.1, -0.1, 0.12]
    body = {"xyz": ",".join(map(str, target)), "duration": "0.5", "wait": "True"}
    answer = http.post("/ik/chain/goto.json", json=body)
    assert answer.status_code == 200, answer.text
    # The answer is the pose read when the goto ended (the sync loops read 50 times a second,
    # later still on a loaded machine); the arm then settles on the target.
    assert np.linalg.norm(np.array(_floats(answer.json()["xyz"])) - target) < 0.02
    robot = ergo[1]
    deadline = time.monotonic() + 5.0
    while np.linalg.norm(np.array(robot.chain.position) - target) >= 0.005:
        assert time.monotonic() < deadline, robot.chain.position
        time.sleep(0.05)
    # a list works too, and a vector orientation
    answer = http.post(
        "/ik/chain/goto.json", json={"xyz": target, "rot": [0, 0, 1], "duration": 0.3}
    )
    assert answer.status_code in (200, 403)


def test_pypot_goto_errors(http: httpx.Client) -> None:
    missing = http.post("/ik/chain/goto.json", json={"xyz": "0.1,0,0.1"})
    assert missing.status_code == 400 and "missing" in missing.json()["error"]
    far = http.post("/ik/chain/goto.json", json={"xyz": "0,0,0.9", "duration": 1})
    assert far.status_code == 403
    assert "nearest point" in far.json()["error"]
    bad = http.post("/ik/chain/goto.json", json={"xyz": "0,0", "duration": 1})
    assert bad.status_code == 400


def test_pypot_rpy_matrix(http: httpx.Client) -> None:
    by_body = http.request("GET", "/ik/chain/rpy.json", json={"r": 0, "p": 0, "y": 1.5707963})
    by_query = http.get("/ik/chain/rpy.json", params={"r": 0, "p": 0, "y": 1.5707963})
    for answer in (by_body, by_query):
        assert answer.status_code == 200
        matrix = np.array(answer.json()["rpy"])
        assert matrix @ [1, 0, 0] == pytest.approx([0, 1, 0], abs=1e-6)
    assert http.get("/ik/chain/rpy.json", params={"r": "a"}).status_code == 400


def test_v1_chains(http: httpx.Client) -> None:
    listed = http.get("/api/v1/chains").json()
    assert [c["name"] for c in listed] == ["chain"]
    one = http.get("/api/v1/chains/chain").json()
    assert one["motors"] == ["m1", "m2", "m3", "m4", "m5", "m6"]
    assert one["base"] == "base_link" and len(one["pose"]) == 4
    assert http.get("/api/v1/chains/nope").status_code == 404


def test_v1_forward_solve_goto(http: httpx.Client, ergo: tuple[str, Robot]) -> None:
    pose = http.post("/api/v1/chains/chain/forward", json={"joints": {"m2": -30, "m3": 20}}).json()
    target = pose["position"]
    solved = http.post("/api/v1/chains/chain/solve", json={"position": target})
    assert solved.status_code == 200
    angles = solved.json()["angles"]
    assert np.linalg.norm(ergo[1].chain.forward(angles)[:3, 3] - target) < 1e-3
    moved = http.post(
        "/api/v1/chains/chain/goto", json={"position": target, "duration": 0.5, "wait": True}
    )
    assert moved.status_code == 200, moved.text
    assert np.linalg.norm(np.array(moved.json()["position"]) - target) < 0.005
    straight = http.post(
        "/api/v1/chains/chain/goto",
        json={"position": [0.1, -0.1, 0.12], "duration": 0.5, "wait": True, "linear": True},
    )
    assert straight.status_code == 200, straight.text


def test_v1_errors(http: httpx.Client) -> None:
    far = http.post("/api/v1/chains/chain/solve", json={"position": [0, 0, 0.9]})
    assert far.status_code == 422 and "nearest point" in far.json()["detail"]
    both = {"position": [0.1, 0, 0.1], "orientation": [0, 0, 1], "rpy_deg": [0, 0, 0]}
    assert http.post("/api/v1/chains/chain/solve", json=both).status_code == 422
    assert http.post("/api/v1/chains/chain/solve", json={"position": [0.1]}).status_code == 422


def test_openapi_lists_the_chain_routes(http: httpx.Client) -> None:
    paths = http.get("/openapi.json").json()["paths"]
    for path in ("/api/v1/chains", "/api/v1/chains/{chain}/goto", "/ik/{chain}/goto.json"):
        assert path in paths
