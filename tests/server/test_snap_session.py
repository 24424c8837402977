"""A teacher's Snap! session replayed in order on poppy's Snap! server (a virtual Ergo Jr).

The session and pypot 5.0.2's answers to it are in ``data/snap_session.json`` (recorded from
pypot's Snap! server over ``poppy emulate`` by ``bench/peers/record_snap_session.py``). Where
pypot's answer is deterministic, poppy answers the same text; where the robot moved, its state
is checked; where pypot answered 500, poppy answers a 4xx line starting with ``Error``.
"""

from __future__ import annotations

import json
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import httpx
import pytest

from poppy_core import from_profile
from poppy_core.motion import SimplePosture, list_moves, load_move
from poppy_core.robot import Robot
from poppy_core.server.snap import SnapServer, start_snap_server
from tests.helpers.waiting import http_timeout
from tests.server.snap_helpers import near, served_ergo, wait_until

SESSION = json.loads((Path(__file__).parent / "data" / "snap_session.json").read_text())
STEPS: list[dict[str, Any]] = SESSION["steps"]


@pytest.fixture(scope="module")
def snap(moves_folder: str) -> Iterator[tuple[Robot, SnapServer, httpx.Client]]:
    """A virtual Ergo Jr (with its behaviours) served by the Snap! server on a free port."""
    yield from served_ergo()


def test_the_session_answers_as_pypot_and_moves_the_robot(
    snap: tuple[Robot, SnapServer, httpx.Client],
) -> None:
    robot, server, http = snap
    answers: dict[int, httpx.Response] = {}
    for index, step in enumerate(STEPS):
        if step["path"] == "/ik/chain/endeffector":
            # the tip is compared with the chain's position read after the answer: the arm must
            # have stopped (a loaded machine may still be ending the last move)
            assert wait_until(lambda: still(robot)), "the arm did not come to rest"
        answer = http.get(step["path"])
        answers[index] = answer
        pypot = step["pypot"]
        where = f"step {index} {step['path']} ({step['what']})"
        assert "\n" not in answer.text, where
        if step["compare"]:
            assert (answer.status_code, answer.text) == (pypot["status"], pypot["text"]), where
        elif pypot["status"] >= 500:
            # pypot fails; poppy does the right thing or refuses in one line
            assert answer.status_code == 200 or (
                400 <= answer.status_code < 500 and answer.text.startswith("Error: ")
            ), where
        check_state(robot, server, step["path"], answer)


def still(robot: Robot, window_s: float = 0.2, tolerance_deg: float = 0.05) -> bool:
    """No motor moved more than ``tolerance_deg`` during ``window_s``."""
    before = [m.present_position for m in robot.motors]
    time.sleep(window_s)
    after = [m.present_position for m in robot.motors]
    return all(abs(a - b) <= tolerance_deg for a, b in zip(before, after, strict=True))


def check_state(robot: Robot, server: SnapServer, path: str, answer: httpx.Response) -> None:
    """The robot's state after the step at ``path`` (polled: motion takes time)."""
    service = server.service
    if path.startswith("/motors/set/registers/m1:compliant"):
        assert all(not m.compliant for m in robot.motors)
    elif path == "/motor/m3/set/led/blue":
        assert [m.led for m in robot.motors[:3]] == ["red", "green", "blue"]
    elif path == "/motor/m1/goto/30/0.5":
        assert wait_until(lambda: near(robot.m1.present_position, 30))
    elif path.startswith("/motors/set/goto/"):
        assert wait_until(
            lambda: near(robot.m2.present_position, -20) and near(robot.m3.present_position, 15)
        )
    elif path == "/motors/get/positions":
        values = [float(v) for v in answer.text.split(";")]
        assert len(values) == 6 and near(values[0], 30) and near(values[1], -20)
    elif path == "/primitive/dance/start":
        assert service.primitive("dance").is_alive()
    elif path == "/primitive/dance/pause":
        assert service.primitive("dance").describe()["state"] == "paused"
    elif path == "/primitive/dance/stop":
        assert not service.primitive("dance").is_alive()
    elif path == "/motor/m1/goto/-20/0.6":
        assert wait_until(lambda: near(robot.m1.present_position, -20))
        time.sleep(0.3)  # a few frames at the end of the move
    elif path == "/primitive/MoveRecorder/wave/stop":
        # the same library as `poppy record`
        assert "wave" in [entry.name for entry in list_moves()]
        move = load_move("wave")
        assert list(move.motors) == ["m1", "m2", "m3"]
        assert near(move.frame(0)["m1"], 30, 3) and near(move.frame(len(move) - 1)["m1"], -20, 3)
    elif path == "/motor/m1/goto/0/0.5":
        assert wait_until(lambda: near(robot.m1.present_position, 0))
    elif path.startswith("/primitive/MovePlayer/wave/start"):
        duration = float(answer.text)
        full = load_move("wave").duration_s
        factor = 2.0 if "/start/2" in path else 1.0
        assert duration == pytest.approx(full / factor, abs=0.01)
        assert wait_until(lambda: "wave" not in service.moves.playing())
        end = 30 if path.endswith("/backwards") else -20
        assert wait_until(lambda: near(robot.m1.present_position, end, 3))
    elif path == "/primitive/MoveRecorder/wave/remove":
        assert "wave" not in [entry.name for entry in list_moves()]
    elif path.startswith("/ik/chain/goto/"):
        assert answer.text == "Done!"
        chain = robot.chain
        target = [0.02, -0.15, 0.16]
        assert wait_until(
            lambda: sum((a - b) ** 2 for a, b in zip(chain.position, target, strict=True)) < 1e-4
        )
    elif path == "/ik/chain/endeffector":
        parts = answer.text.split(",")
        assert len(parts) == 3
        tip = [float(v) for v in parts]
        assert tip == pytest.approx([round(float(v), 4) for v in robot.chain.position], abs=2e-3)


@pytest.mark.parametrize(
    ("path", "status", "says"),
    [
        ("/motor/m9/get/present_position", 404, "no motor 'm9'"),
        ("/motors/nope", 404, "no group 'nope'"),
        ("/motors/m1;m9/get/led", 404, "no motor 'm9'"),
        ("/motor/m1/get/nothing", 404, "no register 'nothing'"),
        ("/motor/m1/set/goal_position/abc", 400, "expected a number"),
        ("/motor/m1/set/goal_position/nan", 400, "must be a finite number"),
        ("/motor/m1/set/goal_position/inf", 400, "must be a finite number"),
        ("/motor/m1/set/goal_position/-Infinity", 400, "must be a finite number"),
        ("/motor/m1/set/goal_position/1e309", 400, "must be a finite number"),
        ("/motors/set/registers/m1:moving_speed:NaN", 400, "must be a finite number"),
        ("/motor/m1/set/goal_position/" + "9" * 400, 400, "must be a finite number"),
        ("/motor/m1/set/compliant/2", 400, "must be true or false (or 1 or 0)"),
        ("/motor/m1/set/compliant/yes", 400, "must be true or false (or 1 or 0)"),
        ("/motor/m1/set/compliant/__import__('os')", 400, "must be true or false"),
        ("/motor/m1/goto/10/-1", 400, "duration"),
        ("/motors/set/goto/m1:10", 400, "motor:position:duration"),
        ("/motors/set/registers/m1:led", 400, "motor:register:value"),
        ("/primitive/nope/start", 404, "no primitive 'nope'"),
        ("/primitive/dance/get/nothing", 404, "no property 'nothing'"),
        ("/primitive/MovePlayer/nope/start", 404, "no move 'nope'"),
        ("/primitive/MovePlayer/a.b/start", 404, "no move 'a.b'"),  # a name, as in the CLI
        ("/primitive/MovePlayer/.b/start", 400, "not a move name"),
        ("/primitive/MoveRecorder/r1/start/m1;zz", 404, "no motor 'zz'"),
        ("/ik/nochain/endeffector", 404, "does not exist"),
        ("/ik/chain/goto/5/5/5/1", 400, "cannot reach"),
        ("/ik/chain/goto/a/0/0/1", 400, "x must be a number"),
        ("/snap/nope", 404, "no Snap! project"),
        ("/detect/nope", 404, "no card 'nope' (cards: "),
        ("/no/such/route", 404, "no Snap! route"),
    ],
)
def test_refusals_are_one_line_4xx(
    snap: tuple[Robot, SnapServer, httpx.Client], path: str, status: int, says: str
) -> None:
    answer = snap[2].get(path)
    assert answer.status_code == status, answer.text
    assert answer.text.startswith("Error: ") and says in answer.text
    assert "\n" not in answer.text and answer.headers["content-type"].startswith("text/plain")


def test_values_read_as_pypot_writes_them(snap: tuple[Robot, SnapServer, httpx.Client]) -> None:
    robot, _, http = snap
    assert http.get("/motor/m4/set/compliant/false").text == "Done!"  # Snap!'s own spelling
    assert not robot.m4.compliant
    assert http.get("/motor/m4/get/registers").text.startswith("['")
    assert http.get("/primitive/dance/methodes").text == "start/stop/pause/resume"
    assert http.get("/primitive/dance/set/tempo_scale/0.5").text == ""
    assert http.get("/primitive/dance/get/tempo_scale").text == "0.5"
    # pypot's get/<attribute> read the primitive's state too: nothing (200) when false
    still = SimplePosture(robot, 60.0, {"m1": robot.m1.present_position})
    robot.attach_primitive(still, "snap_state_probe")
    for state in ("running", "started"):
        answer = http.get(f"/primitive/snap_state_probe/get/{state}")
        assert (answer.status_code, answer.text) == (200, "")
    still.start()
    try:
        assert http.get("/primitive/snap_state_probe/get/running").text == "True"
        assert http.get("/primitive/snap_state_probe/get/started").text == "True"
    finally:
        still.stop()
    assert http.get("/primitive/snap_state_probe/get/running").text == ""
    assert http.get("/motor/m3/set/compliant/false").text == "Done!"  # a compliant one stays
    assert http.get("/motors/set/positions/5;6;7;").text == "Done!"
    assert wait_until(lambda: near(robot.m3.present_position, 7))
    assert http.get("/ip/").text == "127.0.0.1"
    frame = http.get("/frame.png")  # the Ergo Jr's camera (blank when simulated without MuJoCo)
    assert frame.status_code == 200 and frame.content.startswith(b"\x89PNG")
    assert http.get("/detect/caribou").text == "False"  # no card in view


@pytest.mark.parametrize(
    ("path", "compliant"),
    [
        # pypot's own block "set motor(s) ... compliant/stiff" sends 1 and 0 (issue 23)
        ("/motors/set/registers/m5:compliant:0;m6:compliant:0", False),
        ("/motors/set/registers/m5:compliant:1;m6:compliant:1", True),
        ("/motor/m5/set/compliant/0", False),
        ("/motor/m5/set/compliant/1", True),
        ("/motor/m5/set/compliant/False", False),
        ("/motor/m5/set/compliant/True", True),
        ("/motor/m5/set/compliant/false", False),
        ("/motor/m5/set/compliant/true", True),
    ],
)
def test_booleans_as_pypot_blocks_write_them(
    snap: tuple[Robot, SnapServer, httpx.Client], path: str, compliant: bool
) -> None:
    robot, _, http = snap
    for motor in (robot.m5, robot.m6):
        motor.compliant = not compliant
    answer = http.get(path)
    assert (answer.status_code, answer.text) == (200, "Done!")
    assert robot.m5.compliant is compliant
    if "m6" in path:
        assert robot.m6.compliant is compliant


def test_snap_berkeley_edu_is_allowed_and_other_pages_are_not(
    snap: tuple[Robot, SnapServer, httpx.Client],
) -> None:
    http = snap[2]
    allowed = http.get("/motors/motors", headers={"Origin": "https://snap.berkeley.edu"})
    assert allowed.status_code == 200
    assert allowed.headers["access-control-allow-origin"] == "https://snap.berkeley.edu"
    preflight = http.options(
        "/snap-blocks.xml",
        headers={
            "Origin": "https://snap.berkeley.edu",
            "Access-Control-Request-Method": "GET",
            "Access-Control-Request-Private-Network": "true",
        },
    )
    assert preflight.status_code == 204
    assert preflight.headers["access-control-allow-private-network"] == "true"
    assert http.get("/motors/motors", headers={"Origin": "https://evil.example"}).status_code == 403
    linked = http.get("/motor/m1/goto/0/1", headers={"Sec-Fetch-Site": "cross-site"})
    assert linked.status_code == 403  # a link or an image on another site cannot move it
    blocks = http.get("/snap-blocks.xml", headers={"Sec-Fetch-Site": "cross-site"})
    assert blocks.status_code == 200  # documents open from a link
    assert http.get("/motors/motors", headers={"Host": "evil.example"}).status_code == 400


def test_a_token_is_needed_and_carried_by_the_blocks(moves_folder: str) -> None:
    with from_profile("ergo-jr", sim=True) as robot:
        server = start_snap_server(robot, port=0, token="s3cret/+")
        try:
            base = f"http://127.0.0.1:{server.port}"
            assert httpx.get(f"{base}/motors/motors", timeout=http_timeout(20)).status_code == 401
            assert httpx.get(f"{base}/snap-blocks.xml", timeout=http_timeout(20)).status_code == 401
            ok = httpx.get(
                f"{base}/motors/motors", params={"token": "s3cret/+"}, timeout=http_timeout(20)
            )
            assert ok.text == "m1/m2/m3/m4/m5/m6"
            assert server.editor_url.endswith("/snap-blocks.xml?token=s3cret%2F%2B")
            xml = httpx.get(server.blocks_url, timeout=http_timeout(20)).text
            assert xml.count("<l>?token=s3cret%2F%2B</l>") >= 20  # every block's URL
            header = {"Authorization": "Bearer s3cret/+"}
            assert (
                httpx.get(f"{base}/ip/", headers=header, timeout=http_timeout(20)).text
                == "127.0.0.1"
            )
        finally:
            server.stop()
