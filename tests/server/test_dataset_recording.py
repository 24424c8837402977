"""A LeRobot dataset recorded on a served robot (``/api/v1/recording``): by hand and from a move,
lerobot-record's three controls (end the episode, record it again, stop) with the effects they
have on a terminal, one recording at a time, every bad input a 422 in one line, and LeRobot's
own ``LeRobotDataset`` (0.4.4, its venv) loading what was written."""

from __future__ import annotations

import json
import math
import os
import signal
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import httpx
import pyarrow.parquet as pq
import pytest

from poppy_core import from_profile
from poppy_core.assembly import Listen, ServerSet, ServeSpec, serve
from poppy_core.motion import Move, save_move
from tests.helpers.cli import command_env
from tests.helpers.json_lines import JsonChild
from tests.helpers.lerobot_venv import oracle_fixture
from tests.helpers.processes import reap, start
from tests.helpers.server import serve_robot
from tests.helpers.waiting import eventually, http_timeout

pytestmark = pytest.mark.slow
WAVE = Move(10.0, ["m1", "m2"], [[20 * math.sin(k / 5), 10.0] for k in range(300)])  # 30 s
POPPY = [sys.executable, "-m", "poppy_cli"]
QUICK = {"fps": 10, "reset_s": 0, "cameras": []}


oracle = oracle_fixture()


@pytest.fixture
def home(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """LeRobot's folder (``$HF_LEROBOT_HOME``), where the served robot writes its datasets."""
    monkeypatch.setenv("HF_LEROBOT_HOME", str(tmp_path / "lerobot"))
    monkeypatch.setenv("POPPY_MOVES_DIR", str(tmp_path / "library"))
    save_move(WAVE, "wave")
    return tmp_path / "lerobot"


@pytest.fixture
def served(home: Path) -> Iterator[ServerSet]:
    with from_profile("ergo-jr", sim=True) as robot, serve(robot, ServeSpec(http=Listen())) as s:
        yield s


@pytest.fixture
def http(served: ServerSet) -> Iterator[httpx.Client]:
    assert served.http is not None
    with httpx.Client(base_url=served.http.url, timeout=http_timeout(30.0)) as client:
        yield client


def record(http: httpx.Client, **asked: Any) -> dict[str, Any]:
    answer = http.post("/api/v1/recording", json=asked)
    assert answer.status_code == 200, answer.text
    state: dict[str, Any] = answer.json()
    assert state["active"] is True
    return state


def state(http: httpx.Client) -> dict[str, Any]:
    answer = http.get("/api/v1/recording")
    assert answer.status_code == 200, answer.text
    found: dict[str, Any] = answer.json()
    return found


def until(http: httpx.Client, what: str, check: Any) -> dict[str, Any]:
    """The recording's state once ``check(state)`` holds."""
    seen: list[dict[str, Any]] = []

    def holds() -> bool:
        seen.append(state(http))
        return bool(check(seen[-1]))

    assert eventually(holds, 60.0), f"{what}: {seen[-1]}"
    return seen[-1]


def done(http: httpx.Client) -> dict[str, Any]:
    return until(http, "the recording ends", lambda s: not s["active"] and s["phase"] == "done")


def press(http: httpx.Client, control: str) -> dict[str, Any]:
    answer = http.post(f"/api/v1/recording/{control}")
    assert answer.status_code == 200, answer.text
    pressed: dict[str, Any] = answer.json()
    return pressed


def rows(root: Path) -> dict[str, list[Any]]:
    """Every frame the dataset's data files hold, in order."""
    columns: dict[str, list[Any]] = {}
    for path in sorted((root / "data").rglob("*.parquet")):
        for key, values in pq.read_table(path).to_pydict().items():
            columns.setdefault(key, []).extend(values)
    return columns


def test_by_hand_with_the_robots_camera_loads_in_lerobot(
    http: httpx.Client, home: Path, oracle: JsonChild
) -> None:
    assert state(http) == {"active": False, "phase": "idle"} | {
        k: None for k in state(http) if k not in ("active", "phase")
    }
    started = record(
        http,
        repo_id="class/by_hand",
        task="wave at the class",
        source="by_hand",
        episodes=2,
        episode_s=1.5,
        reset_s=0,
        fps=10,
    )
    assert started["folder"] == str(home / "class/by_hand") and started["cameras"] == ["camera"]
    # the motors are the recording's: a v1 goal is refused, naming it
    answer = http.put("/api/v1/motors/m2/registers/goal_position", json={"value": 10})
    assert answer.status_code == 409 and "dataset recording class/by_hand" in answer.text
    live = until(http, "frames counted", lambda s: s["frames"] > 2 or not s["active"])
    assert live["episodes"] == 2 and live["episode"] in (1, 2)
    ended = done(http)
    assert [e["episode"] for e in ended["saved"]] == [0, 1] and ended["total_episodes"] == 2
    assert ended["error"] is None
    # the motors are free again
    assert "dataset recording" not in str(http.get("/api/v1/motors").json())
    root = home / "class/by_hand"
    frames = sum(e["frames"] for e in ended["saved"])
    seen = oracle.ask("load", str(root), "class/by_hand", f"0,{frames - 1}")
    assert (seen["len"], seen["num_episodes"], seen["fps"]) == (frames, 2, 10)
    assert seen["tasks"] == ["wave at the class"]
    assert seen["features"]["observation.images.camera"]["shape"] == [480, 640, 3]
    first, last = seen["items"]
    assert first["observation.images.camera"]["shape"] == [3, 480, 640]
    assert (first["episode_index"], last["episode_index"]) == (0, 1)


def test_a_move_with_rerecord_end_episode_and_stop(
    http: httpx.Client, home: Path, oracle: JsonChild
) -> None:
    record(
        http,
        repo_id="class/wave",
        task="wave",
        source="move",
        move="wave",
        episodes=3,
        episode_s=60,
        **{**QUICK, "reset_s": 60},
    )
    # the move plays with its lease, as a v1 play; a second recording is refused in one line
    assert eventually(lambda: http.get("/api/v1/moves/status").json()["playing"] == ["wave"])
    again = http.post(
        "/api/v1/recording", json={"repo_id": "class/other", "task": "t", "source": "by_hand"}
    )
    assert again.status_code == 409 and "\n" not in again.json()["detail"]
    assert "class/wave" in again.json()["detail"]
    # ← : the take is dropped, episode 1 recorded again (after a reset)
    take = until(http, "a take", lambda s: s["frames"] >= 5)
    assert take["phase"] == "recording" and take["episode"] == 1
    dropped = press(http, "rerecord")
    assert dropped["episode"] == 1
    # then the reset, as lerobot-record's: → ends it
    reset = until(http, "the reset", lambda s: s["phase"] == "resetting")
    assert (reset["episode"], reset["rerecorded"], reset["saved"]) == (1, 1, [])
    press(http, "end-episode")
    second = until(http, "the second take", lambda s: s["rerecorded"] == 1 and s["frames"] >= 15)
    assert second["episode"] == 1 and second["saved"] == []
    # → : episode 1 saved, the reset under way; → again ends the reset
    press(http, "end-episode")
    reset = until(http, "the reset", lambda s: s["phase"] == "resetting")
    assert reset["episode"] == 2 and [e["episode"] for e in reset["saved"]] == [0]
    assert http.get("/api/v1/moves/status").json()["playing"] == []
    press(http, "end-episode")
    until(http, "episode 2", lambda s: s["phase"] == "recording" and s["frames"] >= 15)
    # Esc: episode 2 saved, the recording over (episode 3 never starts)
    press(http, "stop")
    ended = done(http)
    assert [e["episode"] for e in ended["saved"]] == [0, 1] and ended["rerecorded"] == 1
    assert http.post("/api/v1/recording/stop").status_code == 409  # nothing under way
    root = home / "class/wave"
    saved = [e["frames"] for e in ended["saved"]]
    data = rows(root)
    # the dropped take's frames are nowhere: episode 0 is the second take alone
    assert len(data["frame_index"]) == sum(saved)
    assert data["episode_index"] == [0] * saved[0] + [1] * saved[1]
    assert data["frame_index"] == list(range(saved[0])) + list(range(saved[1]))
    actions = [a[0] for a in data["action"]]
    assert max(actions) - min(actions) > 1.0  # the move's goals for m1
    seen = oracle.ask("load", str(root), "class/wave", "0")
    assert (seen["len"], seen["num_episodes"]) == (sum(saved), 2)
    info = json.loads((root / "meta/info.json").read_text())
    assert info["total_episodes"] == 2 and info["total_frames"] == sum(saved)


BAD = [
    ({"fps": 0}, "fps"),
    ({"fps": 1e9}, "fps"),
    ({"fps": 12.5}, "fps"),
    ({"task": "two\nlines"}, "control character"),
    ({"task": "esc \x1b[31m"}, "control character"),
    ({"cameras": ["nope"]}, "no camera 'nope'"),
    ({"episodes": 0}, "episodes"),
    ({"episode_s": -1}, "seconds"),
    ({"reset_s": 1e9}, "seconds"),
    ({"repo_id": "no_slash"}, "user/name"),
    ({"repo_id": "../up"}, "user/name"),
    ({"source": "leader"}, "one source"),
    ({"source": "move", "move": "absent"}, "no move 'absent'"),
    ({"source": "primitive", "primitive": "absent"}, "no primitive 'absent'"),
    ({"source": "by_hand", "move": "wave"}, "one source"),
    ({"resume": True}, "no dataset to resume"),
]


@pytest.mark.parametrize(("change", "said"), BAD)
def test_bad_inputs_are_422_in_one_line(
    http: httpx.Client, home: Path, change: dict[str, Any], said: str
) -> None:
    asked = {"repo_id": "class/bad", "task": "t", "source": "by_hand", **QUICK, **change}
    answer = http.post("/api/v1/recording", json=asked)
    assert answer.status_code == 422, answer.text
    detail = answer.json()["detail"]
    assert isinstance(detail, str) and "\n" not in detail and said in detail
    assert state(http)["phase"] == "idle" and not (home / "class/bad").exists()


def test_nan_and_a_dataset_that_exists_are_refused(http: httpx.Client, home: Path) -> None:
    body = '{"repo_id": "class/nan", "task": "t", "source": "by_hand", "fps": NaN}'
    answer = http.post(
        "/api/v1/recording", content=body, headers={"Content-Type": "application/json"}
    )
    assert answer.status_code == 422 and "fps" in answer.json()["detail"], answer.text
    (home / "class/taken").mkdir(parents=True)
    asked = {"repo_id": "class/taken", "task": "t", "source": "by_hand", **QUICK}
    answer = http.post("/api/v1/recording", json=asked)
    assert answer.status_code == 422 and "already exists" in answer.json()["detail"]
    assert list((home / "class/taken").iterdir()) == []  # nothing written in it


def test_ctrl_c_of_poppy_serve_keeps_the_saved_episodes_loadable(
    tmp_path: Path, oracle: JsonChild
) -> None:
    home = tmp_path / "lerobot"
    env = dict(os.environ, **command_env({"HF_LEROBOT_HOME": str(home)}))
    argv = [*POPPY, "serve", "--http", "--http-port", "0", "--sim", "--profile", "ergo-jr"]
    proc = start(argv, env)
    try:
        assert proc.stdout is not None and proc.stderr is not None
        url = proc.stdout.readline().strip()
        assert url.startswith("http://127.0.0.1:"), proc.stderr.read()
        with httpx.Client(base_url=url, timeout=http_timeout(30.0)) as http:
            record(
                http,
                repo_id="class/cut",
                task="a long demo",
                source="by_hand",
                episodes=5,
                episode_s=120,
                reset_s=0,
                fps=10,
            )
            until(http, "episode 1", lambda s: s["frames"] >= 3)
            press(http, "end-episode")
            until(http, "episode 2", lambda s: s["episode"] == 2 and s["frames"] >= 3)
        proc.send_signal(signal.SIGINT)  # Ctrl-C
        assert proc.wait(timeout=120) == 0, proc.stderr.read()
    finally:
        reap(proc)
    root = home / "class/cut"
    info = json.loads((root / "meta/info.json").read_text())
    assert info["total_episodes"] == 2  # the finished one, and the one under way saved (as Esc)
    assert not [p for p in root.rglob("*") if p.name.startswith(".")]  # no leftover
    seen = oracle.ask("load", str(root), "class/cut", "0")
    assert (seen["len"], seen["num_episodes"]) == (info["total_frames"], 2)


def test_the_token_and_the_origin_guard_cover_the_routes(home: Path) -> None:
    asked = {"repo_id": "class/guarded", "task": "t", "source": "by_hand", **QUICK}
    cross_site = {"Origin": "https://evil.example", "Sec-Fetch-Site": "cross-site"}
    served = serve_robot(from_profile("ergo-jr", sim=True), token="s3cret-recording")
    url = next(served).url
    try:
        with httpx.Client(base_url=url, timeout=http_timeout(30.0)) as http:
            for path in ("/api/v1/recording", "/api/v1/recording/stop"):
                assert http.post(path, json=asked).status_code == 401
            assert http.get("/api/v1/recording").status_code == 401
            bearer = {"Authorization": "Bearer s3cret-recording"}
            refused = http.post("/api/v1/recording", json=asked, headers=bearer | cross_site)
            assert refused.status_code == 403, refused.text
            assert not (home / "class/guarded").exists()
            answer = http.post("/api/v1/recording", json=asked, headers=bearer)
            assert answer.status_code == 200, answer.text
            stopped = http.post("/api/v1/recording/stop", headers=bearer)
            assert stopped.status_code == 200, stopped.text
    finally:
        served.close()
    assert json.loads((home / "class/guarded/meta/info.json").read_text())["total_episodes"] <= 1


def test_the_pages_stop_ends_the_recording_as_esc(http: httpx.Client, home: Path) -> None:
    record(
        http,
        repo_id="class/halted",
        task="wave",
        source="move",
        move="wave",
        episodes=3,
        episode_s=60,
        **QUICK,
    )
    until(http, "frames", lambda s: s["frames"] >= 3)
    answer = http.post("/api/v1/web/stop", json={"then": "hold"})
    assert answer.status_code == 200, answer.text
    ended = done(http)
    assert [e["episode"] for e in ended["saved"]] == [0] and ended["error"] is None
    assert http.get("/api/v1/moves/status").json()["playing"] == []
    info = json.loads((home / "class/halted/meta/info.json").read_text())
    assert info["total_episodes"] == 1


def test_a_primitive_runs_each_episode_and_a_running_one_is_refused(
    http: httpx.Client, home: Path
) -> None:
    assert http.post("/api/v1/primitives/dance/start").status_code == 200
    asked = {"repo_id": "class/dance", "task": "dance", "source": "primitive", **QUICK}
    refused = http.post("/api/v1/recording", json={**asked, "primitive": "dance"})
    assert refused.status_code == 409 and "dance is running" in refused.json()["detail"]
    assert http.post("/api/v1/primitives/dance/stop").status_code == 200
    record(http, **asked, primitive="dance", episodes=2, episode_s=1)
    until(http, "the primitive running", lambda s: s["frames"] >= 2 or not s["active"])
    ended = done(http)
    assert [e["episode"] for e in ended["saved"]] == [0, 1]
    assert http.get("/api/v1/primitives/dance").json()["state"] != "running"
    data = rows(home / "class/dance")
    assert data["episode_index"].count(1) == ended["saved"][1]["frames"]


def test_done_means_the_dataset_is_written_finishing_until_then(
    http: httpx.Client, home: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The takes are in but the dataset is still being written (a loaded machine, long videos):
    the state says `finishing`, still active; `done` only once the recording is over, so a page
    that reads "done" can record again at once."""
    from poppy_core.dataset.writer import DatasetWriter

    close = DatasetWriter.close

    def slow_close(self: DatasetWriter) -> None:
        time.sleep(1.0)
        close(self)

    monkeypatch.setattr(DatasetWriter, "close", slow_close)
    record(
        http, repo_id="class/slow", task="wave", source="by_hand", episodes=1, episode_s=60, **QUICK
    )
    until(http, "frames", lambda s: s["frames"] >= 3)
    press(http, "stop")
    seen = [state(http)]
    while seen[-1]["active"]:
        seen.append(state(http))
    assert all(s["phase"] != "done" for s in seen if s["active"]), seen
    assert "finishing" in [s["phase"] for s in seen], [s["phase"] for s in seen]
    assert seen[-1]["phase"] == "done" and [e["episode"] for e in seen[-1]["saved"]] == [0]
