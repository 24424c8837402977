"""`poppy dataset record|info|list`: episodes from a robot (simulated, or virtual motors moved by
a test hand) into a LeRobot dataset; bad inputs refused in one line before a robot is built."""

from __future__ import annotations

import json
import math
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pyarrow.parquet as pq
import pytest

from poppy_core.emulator import VirtualBus
from tests.helpers.bus import emulate_bus
from tests.helpers.cli import no_user_settings, run_poppy

pytestmark = pytest.mark.slow
QUICK = ("--fps", "10", "--episode-s", "1", "--reset-s", "0")


@pytest.fixture(autouse=True)
def settings(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("HF_LEROBOT_HOME", str(tmp_path / "lerobot"))
    return no_user_settings(tmp_path, monkeypatch, moves=True)


def frames_of(root: Path, episode: int) -> dict[str, list[Any]]:
    data: dict[str, list[Any]] = pq.read_table(
        root / f"data/chunk-000/file-{episode:03d}.parquet"
    ).to_pydict()
    return data


def test_a_primitive_recorded_with_a_camera(tmp_path: Path) -> None:
    root = tmp_path / "ds"
    result = run_poppy(
        "dataset",
        "record",
        "poppy/dance",
        "--root",
        str(root),
        "--profile",
        "ergo-jr",
        "--sim",
        "--primitive",
        "dance",
        "--episodes",
        "2",
        "--task",
        "dance for the class",
        "--camera",
        "top=dummy:64x48",
        *QUICK,
        "--json",
    )
    assert result.code == 0, result.stderr
    summary = result.json()
    assert [e["episode"] for e in summary["saved"]] == [0, 1]
    assert summary["total_episodes"] == 2 and summary["frames"] > 4
    info = json.loads((root / "meta/info.json").read_text())
    assert info["robot_type"] == "ergo-jr"
    assert info["features"]["action"]["names"] == [f"m{i}.pos" for i in range(1, 7)]
    assert info["features"]["observation.images.top"]["shape"] == [48, 64, 3]
    frames = frames_of(root, 1)
    assert frames["episode_index"][0] == 1 and frames["frame_index"][:3] == [0, 1, 2]
    listed = run_poppy("dataset", "list", str(root), "--json").json()
    assert [row["episode"] for row in listed] == [0, 1]
    assert listed[0]["tasks"] == ["dance for the class"]
    shown = run_poppy("dataset", "info", str(root), "--json").json()
    assert (shown["episodes"], shown["cameras"], shown["fps"]) == (2, ["top"], 10)
    # --resume adds to it; the default root is LeRobot's ($HF_LEROBOT_HOME/REPO_ID)
    again = run_poppy(
        "dataset",
        "record",
        "poppy/dance",
        "--root",
        str(root),
        "--resume",
        "--profile",
        "ergo-jr",
        "--sim",
        "--primitive",
        "dance",
        "--task",
        "dance",
        "--camera",
        "top=dummy:64x48",
        *QUICK,
        "--json",
    )
    assert again.code == 0, again.stderr
    assert again.json()["total_episodes"] == 3


@pytest.fixture
def hand_bus() -> Iterator[tuple[VirtualBus, str]]:
    with emulate_bus("XL-320:1-6", protocol=2) as (bus, url):
        yield bus, url


def waving(bus: VirtualBus, stop: threading.Event) -> threading.Thread:
    """A test hand moving every joint of ``bus`` (motor frame) until ``stop``."""

    def wave() -> None:
        began = time.monotonic()
        while not stop.is_set():
            t = time.monotonic() - began
            for k, motor in enumerate(bus.motors):
                motor.move_by_hand(20.0 + 25.0 * math.sin(3.0 * t + k))
            time.sleep(0.01)

    thread = threading.Thread(target=wave, daemon=True)
    thread.start()
    return thread


def test_by_hand_the_action_is_the_next_state(tmp_path: Path, hand_bus: Any) -> None:
    bus, url = hand_bus
    stop = threading.Event()
    hand = waving(bus, stop)
    try:
        result = run_poppy(
            "dataset",
            "record",
            "poppy/hand",
            "--root",
            str(tmp_path / "ds"),
            "--profile",
            "ergo-jr",
            "--port",
            url,
            "--by-hand",
            "--task",
            "wave",
            "--no-cameras",
            *QUICK,
        )
    finally:
        stop.set()
        hand.join()
    assert result.code == 0, result.stderr
    frames = frames_of(tmp_path / "ds", 0)
    states, actions = frames["observation.state"], frames["action"]
    assert len(states) > 3
    assert all(actions[k] == states[k + 1] for k in range(len(states) - 1))
    assert actions[-1] == states[-1]
    first = [row[0] for row in states]
    assert max(first) - min(first) > 5.0  # the hand moved m1 during the episode


def test_teleoperated_the_action_is_the_leaders(tmp_path: Path, hand_bus: Any) -> None:
    leader_bus, leader_url = hand_bus
    with emulate_bus("XL-320:1-6", protocol=2) as (_, follower_url):
        stop = threading.Event()
        hand = waving(leader_bus, stop)
        try:
            result = run_poppy(
                "dataset",
                "record",
                "poppy/teleop",
                "--root",
                str(tmp_path / "ds"),
                "--profile",
                "ergo-jr",
                "--port",
                follower_url,
                "--leader",
                "ergo-jr",
                "--leader-port",
                leader_url,
                "--task",
                "copy",
                "--no-cameras",
                "--fps",
                "10",
                "--episode-s",
                "3",
                "--reset-s",
                "0",
            )
        finally:
            stop.set()
            hand.join()
    assert result.code == 0, result.stderr
    frames = frames_of(tmp_path / "ds", 0)
    actions, states = frames["action"], frames["observation.state"]
    assert max(a[0] for a in actions) - min(a[0] for a in actions) > 5.0  # the leader moved
    # the follower copied the leader: by the end its state is near the leader's actions
    late = [row[0] for row in states[len(states) // 2 :]]
    assert max(late) - min(late) > 2.0


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (("--fps", "0"), "fps must be a whole number from 1 to 240, not 0"),
        (("--episode-s", "nan"), "give 0.1 to 3600 seconds"),
        (("--episode-s", "1e9"), "give 0.1 to 3600 seconds"),
        (("--task", "pick\x1b[2Jthe cube"), "control character"),
        (("--camera", "front"), "no camera 'front' on this robot (cameras: camera)"),
        (("--camera", "a/b=0"), "give NAME or NAME=SPEC"),
        (("--by-hand",), "give one source of actions"),
    ],
)
def test_bad_inputs_are_refused_in_one_line(
    tmp_path: Path, args: tuple[str, ...], message: str
) -> None:
    base = [
        "dataset",
        "record",
        "poppy/bad",
        "--root",
        str(tmp_path / "ds"),
        "--profile",
        "ergo-jr",
    ]
    base += ["--sim", "--primitive", "dance", "--task", "task"]
    result = run_poppy(*base, *args)
    assert result.code == 2, result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and message in lines[0], result.stderr
    assert not (tmp_path / "ds").exists()


def test_an_existing_root_is_refused_without_resume(tmp_path: Path) -> None:
    (tmp_path / "ds").mkdir()
    result = run_poppy(
        "dataset",
        "record",
        "poppy/x",
        "--root",
        str(tmp_path / "ds"),
        "--profile",
        "ergo-jr",
        "--sim",
        "--primitive",
        "dance",
        "--task",
        "t",
    )
    assert result.code == 2
    assert "already exists: pass --resume" in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1
