"""`poppy dataset replay|delete-episode`: an episode's actions played on a virtual robot (the
motors reach the recorded positions in order), an episode removed; bad inputs refused in one
line (exit 2) before a robot is built."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from poppy_core.dataset.layout import DatasetSpec
from poppy_core.dataset.writer import DatasetWriter
from tests.helpers.bus import emulate_bus
from tests.helpers.cli import command_env, no_user_settings, run_poppy
from tests.helpers.processes import start
from tests.helpers.waiting import scaled

pytestmark = pytest.mark.slow
MOTORS = tuple(f"m{i}" for i in range(1, 7))


@pytest.fixture(autouse=True)
def settings(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("HF_LEROBOT_HOME", str(tmp_path / "lerobot"))
    return no_user_settings(tmp_path, monkeypatch)


def m1_path(k: int) -> float:
    """m1 of episode 1: from 15° up to 30° (frame 10), down to -17.5° (frame 29), then still."""
    return 15.0 + 1.5 * min(k, 10) - 2.5 * min(max(k - 10, 0), 19)


def write_dataset(root: Path, frames: int = 30, fps: int = 10) -> None:
    """Episode 0: every motor still at 5°; episode 1: m1 as ``m1_path``, m4 from 0 to -29°."""
    writer = DatasetWriter.create(root, DatasetSpec(fps, MOTORS, robot_type="ergo-jr"))
    writer.begin_episode("stay")
    for _ in range(5):
        writer.add_frame([5.0] * 6, [5.0] * 6)
    writer.save_episode()
    writer.begin_episode("wave")
    for k in range(frames):
        action = [m1_path(k), 0.0, 0.0, -float(k % 30), 0.0, 0.0]
        writer.add_frame(action, action)
    writer.save_episode()


@pytest.fixture
def dataset(tmp_path: Path) -> Path:
    root = tmp_path / "lerobot" / "me" / "wave"
    write_dataset(root)
    return root


def test_the_motors_go_through_the_recorded_positions_in_order(dataset: Path) -> None:
    with emulate_bus("XL-320:1-6", protocol=2) as (bus, url):
        # every goal m1 is written, as the motor takes it: a thread polling the goal missed the
        # peak's frames on a busy machine
        goals: list[float] = [bus.motors[0].goal_position_deg]
        m1 = bus.motors[0]
        take = m1.apply_write

        def taken(address: int, data: bytes) -> None:
            take(address, data)
            goals.append(m1.goal_position_deg)

        m1.apply_write = taken  # type: ignore[method-assign]
        try:  # no --root: LeRobot's place for me/wave ($HF_LEROBOT_HOME/me/wave)
            result = run_poppy(
                "dataset",
                "replay",
                "me/wave",
                "--episode",
                "1",
                "--profile",
                "ergo-jr",
                "--port",
                url,
                "--speed",
                "2",
                "--json",
            )
        finally:
            del m1.apply_write
        assert result.code == 0, result.stderr
        summary = result.json()
        assert summary["completed"] and (summary["episode"], summary["frames"]) == (1, 30)
        assert summary["motors"] == list(MOTORS) and summary["speed"] == 2.0
        assert summary["duration_s"] == pytest.approx(2.9 / 2)
        # arrival: every motor at the last frame's action
        last = [m1_path(29), 0.0, 0.0, -29.0, 0.0, 0.0]
        for motor, where in zip(bus.motors, last, strict=True):
            assert motor.goal_position_deg == pytest.approx(where, abs=0.5)
    # shape: a ramp from 0° to the first frame (15°), up to 30°, then down to -17.5°, in order.
    # The bus writes the newest goal each cycle: a cycle the OS ran 50 ms late (a busy machine)
    # skips the frame it outlived, the peak's included, so the peak is any frame within 3° of it
    # (frames 8-11: 27°, 28.5°, 30°, 27.5°).
    first = next(i for i, g in enumerate(goals) if g >= 14.5)
    peak = next(i for i, g in enumerate(goals) if g >= 26.9)
    low = next(i for i, g in enumerate(goals) if g <= -17.0)
    assert first < peak < low
    assert 26.9 <= max(goals) <= 30.5
    assert min(goals) == pytest.approx(-17.5, abs=0.5)
    assert all(g >= -0.5 for g in goals[:peak])  # nothing below the ramp's start before the peak


def test_a_signal_during_replay_exits_130_after_the_summary(tmp_path: Path) -> None:
    root = tmp_path / "long"
    write_dataset(root, frames=600)  # 60 s
    env = dict(os.environ, **command_env({"COLUMNS": "200"}))
    argv = [sys.executable, "-m", "poppy_cli", "dataset", "replay", "me/long", "--root", str(root)]
    proc = start(
        [*argv, "--episode", "1", "--sim", "--profile", "ergo-jr", "--json"],
        env,
        stdin=subprocess.DEVNULL,
    )
    assert proc.stderr is not None
    line = proc.stderr.readline()
    assert line.startswith("replaying episode 1"), line + proc.stderr.read()
    proc.send_signal(signal.SIGINT)
    stdout, stderr = proc.communicate(timeout=scaled(30))
    assert proc.returncode == 130, stderr
    summary = json.loads(stdout)
    assert summary["completed"] is False and summary["played_s"] < 60


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (("--episode", "2"), "no episode 2 in this dataset (episodes: 0 to 1)"),
        (("--episode", "1", "--speed", "0"), "--speed"),
        (("--episode", "1", "--speed", "nan"), "--speed"),
        (("--episode", "-1"), "--episode"),
        (
            ("--episode", "1", "--profile", "poppy-torso"),
            "joints m1, m2, m3, m4, m5, m6 are not motors",
        ),
        (("--episode", "1", "--root", "/nonexistent/ds"), "holds no dataset"),
    ],
)
def test_bad_replays_are_refused_in_one_line(
    dataset: Path, args: tuple[str, ...], message: str
) -> None:
    profile = () if "--profile" in args else ("--profile", "ergo-jr")
    result = run_poppy("dataset", "replay", "me/wave", "--sim", *profile, *args)
    assert result.code == 2, result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and message in lines[0], result.stderr


@pytest.fixture
def three(tmp_path: Path) -> Iterator[Path]:
    root = tmp_path / "three"
    writer = DatasetWriter.create(root, DatasetSpec(10, MOTORS))
    for number, task in enumerate(["a", "b", "a"]):
        writer.begin_episode(task)
        for _ in range(4 + number):
            writer.add_frame([float(number)] * 6, [float(number)] * 6)
        writer.save_episode()
    yield root


def test_delete_episode(three: Path) -> None:
    result = run_poppy(
        "dataset", "delete-episode", "me/three", "--root", str(three), "--episode", "1", "--json"
    )
    assert result.code == 0, result.stderr
    assert result.json() == {
        "root": str(three),
        "deleted": 1,
        "frames": 5,
        "total_episodes": 2,
        "total_frames": 10,
        "total_tasks": 1,
    }
    listed = run_poppy("dataset", "list", str(three), "--json").json()
    assert [(row["episode"], row["frames"], row["tasks"]) for row in listed] == [
        (0, 4, ["a"]),
        (1, 6, ["a"]),
    ]
    # what was episode 2 replays as episode 1
    replayed = run_poppy(
        "dataset",
        "replay",
        "me/three",
        "--root",
        str(three),
        "--episode",
        "1",
        "--sim",
        "--profile",
        "ergo-jr",
        "--json",
    )
    assert replayed.code == 0 and replayed.json()["frames"] == 6
    text = run_poppy(
        "dataset", "delete-episode", "me/three", "--root", str(three), "--episode", "0"
    )
    assert text.code == 0 and "deleted episode 0 (4 frames); 1 episodes" in text.stdout


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (("--episode", "3"), "no episode 3 in this dataset (episodes: 0 to 2)"),
        (("--episode", "0", "--root", "/nonexistent/ds"), "holds no dataset"),
        (("bad name", "--episode", "0"), "is not a dataset name"),
    ],
)
def test_bad_deletions_are_refused_in_one_line(
    three: Path, args: tuple[str, ...], message: str
) -> None:
    name = () if args[0] == "bad name" else ("me/three",)
    root = () if "--root" in args else ("--root", str(three))
    before = sorted((p.name, p.stat().st_mtime_ns) for p in three.rglob("*"))
    result = run_poppy("dataset", "delete-episode", *name, *args, *root)
    assert result.code == 2, result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and message in lines[0], result.stderr
    assert sorted((p.name, p.stat().st_mtime_ns) for p in three.rglob("*")) == before
