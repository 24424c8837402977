"""The temperature monitor's alarm sound: played by the system's player when a motor gets hot."""

from __future__ import annotations

import io
import logging
import stat
import wave
from collections.abc import Iterator
from pathlib import Path

import pytest

from poppy_core.creatures import alarm, safety
from poppy_core.creatures.safety import TemperatureMonitor
from poppy_core.robot import Robot
from tests.creatures.helpers import virtual, wait_until


def _player(folder: Path, code: int = 0) -> tuple[Path, Path]:
    """A player program that notes the file it is asked to play (and its first bytes)."""
    log = folder / "played.txt"
    script = folder / "player"
    script.write_text(
        f'#!/bin/sh\nprintf "%s %s\\n" "$1" "$(head -c 4 "$1")" >> "{log}"\nexit {code}\n'
    )
    script.chmod(script.stat().st_mode | stat.S_IXUSR)
    return script, log


def _played(log: Path) -> list[str]:
    return log.read_text().splitlines() if log.exists() else []


@pytest.fixture
def monitor(ergo: Robot) -> Iterator[TemperatureMonitor]:
    watch = TemperatureMonitor(ergo, freq=10.0)
    yield watch
    watch.stop()
    virtual(ergo, "m2").table.set_si("present_temperature", 30.0)


@pytest.fixture
def cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    return tmp_path / "cache" / "poppy" / "alarm.wav"


def test_the_tone_is_a_half_second_mono_wav() -> None:
    with wave.open(io.BytesIO(alarm.alarm_tone())) as wav:
        assert (wav.getnchannels(), wav.getsampwidth()) == (1, 2)
        assert 0.4 <= wav.getnframes() / wav.getframerate() <= 0.6


def test_a_hot_motor_plays_poppys_tone_then_again_while_it_stays_hot(
    ergo: Robot,
    monitor: TemperatureMonitor,
    tmp_path: Path,
    cache: Path,
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(safety, "ALARM_REPEAT_S", 0.3)
    player, log = _player(tmp_path)
    monitor.player = str(player)
    monitor.start()
    assert wait_until(lambda: monitor.running)
    assert _played(log) == []  # nothing hot: silence
    virtual(ergo, "m2").table.set_si("present_temperature", 70.0)
    assert wait_until(lambda: len(_played(log)) >= 2, 10.0), _played(log)
    assert monitor.hot_motors == ["m2"]
    assert all(line == f"{cache} RIFF" for line in _played(log))  # the cached tone, a WAV
    assert cache.read_bytes() == alarm.alarm_tone()
    virtual(ergo, "m2").table.set_si("present_temperature", 30.0)
    assert wait_until(lambda: monitor.hot_motors == [], 5.0)
    monitor.stop()
    heard = len(_played(log))
    assert monitor.alarm.played >= heard >= 2  # one process per alarm, none after it cooled


def test_pypots_arguments_play_the_given_sound(
    ergo: Robot, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    player, log = _player(tmp_path)
    sound = tmp_path / "error.wav"
    sound.write_bytes(alarm.alarm_tone())
    # poppy-torso's own call: TemperatureMonitor(robot, sound=...), player 'aplay' by default
    watch = TemperatureMonitor(ergo, 10.0, temp_limit=40, player=str(player), sound=sound)
    assert (watch.temp_limit, watch.temperature_limit) == (40.0, 40.0)
    try:
        watch.start()
        virtual(ergo, "m2").table.set_si("present_temperature", 45.0)
        assert wait_until(lambda: _played(log) != [], 10.0)
        assert _played(log)[0] == f"{sound} RIFF"
    finally:
        watch.stop()
        virtual(ergo, "m2").table.set_si("present_temperature", 30.0)


def test_without_a_player_the_log_says_so_once(
    ergo: Robot,
    monitor: TemperatureMonitor,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    caplog: pytest.LogCaptureFixture,
) -> None:
    monkeypatch.setattr(safety, "ALARM_REPEAT_S", 0.2)
    empty = tmp_path / "bin"
    empty.mkdir()
    monkeypatch.setenv("PATH", str(empty))
    looked: list[str | None] = []

    def find_player() -> str | None:
        looked.append(found := alarm.shutil.which("aplay"))
        return found

    monkeypatch.setattr(alarm, "find_player", find_player)
    with caplog.at_level(logging.WARNING, logger="poppy_core.creatures"):
        monitor.start()
        virtual(ergo, "m2").table.set_si("present_temperature", 70.0)
        assert wait_until(lambda: monitor.hot_motors == ["m2"], 10.0)
        assert wait_until(lambda: len(looked) >= 3, 10.0)  # three alarms without a player
    lines = [r.getMessage() for r in caplog.records if r.name == "poppy_core.creatures.alarm"]
    assert lines == [
        "no audio player found (aplay, paplay, pw-play, afplay): "
        "the temperature alarm is this log only"
    ]
    assert monitor.alarm.played == 0


def test_a_player_that_fails_is_said_once(
    ergo: Robot,
    monitor: TemperatureMonitor,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    caplog: pytest.LogCaptureFixture,
    cache: Path,
) -> None:
    monkeypatch.setattr(safety, "ALARM_REPEAT_S", 0.2)
    player, log = _player(tmp_path, code=1)
    monitor.player = str(player)
    with caplog.at_level(logging.WARNING, logger="poppy_core.creatures"):
        monitor.start()
        virtual(ergo, "m2").table.set_si("present_temperature", 70.0)
        assert wait_until(lambda: len(_played(log)) >= 3, 10.0)
    failures = [r.getMessage() for r in caplog.records if "did not play" in r.getMessage()]
    assert failures == [
        f"the temperature alarm did not play ({player} exited with 1): no sound device?"
    ]
