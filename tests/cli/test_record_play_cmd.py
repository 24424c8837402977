"""`poppy record` and `poppy play` as subprocesses: signals, saved files, playback, refusals."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from poppy_core.motion import Move, read_move, save_move
from tests.helpers.cli import command_env, keyed, no_user_settings
from tests.helpers.processes import start
from tests.helpers.waiting import scaled

POPPY = [sys.executable, "-m", "poppy_cli"]


@pytest.fixture(autouse=True)
def library(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """An empty move library and no user settings."""
    return no_user_settings(tmp_path, monkeypatch, moves=True)


def start_recording(*args: str) -> subprocess.Popen[str]:
    """`poppy record ARGS` in the background, returned once it says it is recording."""
    env = dict(os.environ, **command_env())
    proc = start([*POPPY, "record", *args], env, stdin=subprocess.DEVNULL)
    assert proc.stderr is not None
    line = proc.stderr.readline()
    assert line.startswith("recording"), line + proc.stderr.read()
    return proc


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_signal_during_record_keeps_a_valid_file(signum: int, library: Path) -> None:
    proc = start_recording("wave", "--sim", "--profile", "ergo-jr", "--motors", "base,m6")
    recording = time.monotonic()
    time.sleep(1.5)
    proc.send_signal(signum)
    stdout, stderr = proc.communicate(timeout=scaled(20))
    ended = time.monotonic()
    assert proc.returncode == 0, stderr
    path = Path(stdout.strip().splitlines()[-1])  # the path alone on the last line
    assert path == library / "wave.move"
    move = read_move(path)
    assert move.motors == ("m1", "m2", "m3", "m6")
    assert move.framerate == 50
    # covers the 1.5 s recorded (it said "recording" a little before its first frame), and no
    # more than the time it ran: it stopped at the signal, however late a loaded machine ran it
    assert 1.3 <= move.duration_s <= ended - recording
    assert len(move) == round(move.duration_s * 50) + 1


def test_killed_recording_keeps_the_last_checkpoint(library: Path) -> None:
    proc = start_recording("crash", "--sim", "--profile", "ergo-jr", "--freq", "25")
    time.sleep(2.5)
    proc.kill()  # no handler runs: only the checkpoints are on disk
    proc.communicate(timeout=scaled(20))
    move = read_move(library / "crash.move")
    assert move.framerate == 25 and len(move.motors) == 6
    assert move.duration_s >= 0.9
    assert not [p for p in library.iterdir() if p.name.endswith(".tmp")]


def test_record_duration_json_and_existing_name(poppy: Any, library: Path) -> None:
    args = ("record", "short", "--sim", "--profile", "ergo-jr", "--duration", "0.5")
    begun = time.monotonic()
    result = poppy(*args, "--json", "--freq", "20")
    took = time.monotonic() - begun
    assert result.code == 0, result.stderr
    data = result.json()
    assert data["path"] == str(library / "short.move") and data["framerate"] == 20
    # 0.5 s on the 20 Hz grid; its end may come late, never after the command returned
    assert 0.45 <= data["duration_s"] <= took
    again = poppy(*args)
    assert again.code == 1 and "--force" in again.stderr  # a refused file: 1, as elsewhere
    assert poppy(*args, "--force").code == 0


def test_record_unknown_motor_is_refused(poppy: Any) -> None:
    result = poppy("record", "x", "--sim", "--profile", "ergo-jr", "--motors", "m1,elbow")
    assert result.code == 2 and "elbow" in result.stderr


def ramp(motors: list[str], goals: list[float], seconds: float = 1.0) -> Move:
    t = np.linspace(0.0, 1.0, int(seconds * 50) + 1)[:, None]
    return Move(50, motors, t * np.array(goals)[None, :])


def checked_json(result: Any) -> Any:
    assert result.code == 0, result.stderr
    return result.json()


def test_play_reaches_the_last_frame_on_an_emulated_bus(poppy: Any, ergo_jr: Any) -> None:
    save_move(ramp(["m1", "m4"], [30.0, -20.0]), "reach")
    bus = ("--profile", "ergo-jr", "--port", ergo_jr.url)
    result = poppy("play", "reach", *bus, "--speed", "2", "--json")
    assert result.code == 0, result.stderr
    data = result.json()
    assert data["completed"] and data["duration_s"] == pytest.approx(0.5)
    assert data["played_s"] >= 0.5  # the move's 1 s at speed 2, never ended early
    status = keyed(checked_json(poppy("robot", "status", *bus, "--json"))["motors"])
    assert status["m1"]["position"] == pytest.approx(30, abs=1.0)
    assert status["m4"]["position"] == pytest.approx(-20, abs=1.0)
    backwards = poppy("play", "reach", *bus, "--reverse", "--loop", "2", "--json")
    assert backwards.code == 0, backwards.stderr
    played = backwards.json()
    assert played["completed"] and (played["loops"], played["reverse"]) == (2, True)
    assert played["duration_s"] == pytest.approx(2.0) and played["played_s"] >= 2.0  # twice 1 s
    status = keyed(checked_json(poppy("robot", "status", *bus, "--json"))["motors"])
    assert status["m1"]["position"] == pytest.approx(0, abs=1.0)


def test_play_a_pypot_file_by_path(poppy: Any, tmp_path: Path) -> None:
    path = tmp_path / "old.json"
    path.write_text(
        '{"framerate": 10.0, "positions": {"0.0": {"m2": [0.0, 0.0]}, "0.1": {"m2": [5.0, 50.0]},'
        ' "0.2": {"m2": [10.0, 50.0]}}}'
    )
    result = poppy("play", str(path), "--sim", "--profile", "ergo-jr")
    assert result.code == 0, result.stderr
    assert "played" in result.stdout and "old.json" in result.stdout


def test_play_refuses_missing_motors_naming_them(poppy: Any) -> None:
    save_move(ramp(["m1", "elbow", "wrist"], [1.0, 2.0, 3.0]), "alien")
    result = poppy("play", "alien", "--sim", "--profile", "ergo-jr")
    assert result.code == 1
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and "elbow, wrist" in lines[0]


def test_play_unknown_move(poppy: Any) -> None:
    result = poppy("play", "nothing", "--sim", "--profile", "ergo-jr")
    assert result.code == 1 and "no move 'nothing'" in result.stderr


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_during_play_exits_130_after_the_summary(signum: int) -> None:
    save_move(ramp(["m1"], [30.0], seconds=60.0), "long")
    env = dict(os.environ, **command_env())
    proc = start(
        [*POPPY, "play", "long", "--sim", "--profile", "ergo-jr", "--json"],
        env,
        stdin=subprocess.DEVNULL,
    )
    assert proc.stderr is not None
    line = proc.stderr.readline()
    assert line.startswith("playing long"), line + proc.stderr.read()
    proc.send_signal(signum)
    stdout, stderr = proc.communicate(timeout=scaled(20))
    assert proc.returncode == 130, stderr
    summary = json.loads(stdout)
    assert summary["completed"] is False and summary["played_s"] < 60


def test_the_recording_s_start_lines_fit_80_columns() -> None:
    from pathlib import Path

    from poppy_cli.commands.record import start_lines

    names = [f"motor_{i}" for i in range(25)]
    for motors, path in (
        (["m1", "m2", "m3", "m4", "m5", "m6"], Path("/root/.local/share/poppy/moves/wave.json")),
        (names, Path("/home/pi/.local/share/poppy/moves/a-long-move-name-of-the-humanoid.json")),
        (["m1"], Path("wave.json")),
    ):
        lines = start_lines(motors, 50, path)
        assert all(len(line) <= 80 for line in lines), lines
        text = " ".join(lines)
        assert str(path) in text and "Enter or Ctrl-C stops" in text
        assert ("m1" in text) if len(motors) < 10 else "25 motors" in text
