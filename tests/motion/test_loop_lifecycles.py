"""The move player's and recorder's threads follow the worker's story: stop joins (even from the
loop's own thread), an error in the loop is logged once and kept, stopping twice is safe."""

from __future__ import annotations

import logging

import numpy as np
import pytest

from poppy_core.motion import Move, MovePlayer, MoveRecorder, PlayProgress
from poppy_core.robot import Robot
from tests.helpers import eventually
from tests.helpers.fixtures import ergo_fixture

ergo = ergo_fixture(sensors=False)


def _move(robot: Robot, duration_s: float = 2.0) -> Move:
    names = [m.name for m in robot.motors][:2]
    frames = int(duration_s * 50)
    positions = np.zeros((frames, len(names)))
    return Move(50.0, names, positions)


def _failures(caplog: pytest.LogCaptureFixture, name: str) -> list[logging.LogRecord]:
    return [r for r in caplog.records if r.getMessage().startswith(f"{name} failed")]


def test_the_player_stopped_from_its_progress_callback_ends_well(ergo: Robot) -> None:
    holder: list[MovePlayer] = []

    def progress(event: PlayProgress) -> None:
        if event.phase == "play":
            holder[0].stop()  # the loop's own thread: only asks

    player = MovePlayer(ergo, _move(ergo), ramp_s=0.0, on_progress=progress)
    holder.append(player)
    player.start()
    assert player.wait(10.0)
    assert player.error is None and player.stopped


def test_an_error_in_the_playback_is_logged_once_and_raised_by_play(
    ergo: Robot, caplog: pytest.LogCaptureFixture, monkeypatch: pytest.MonkeyPatch
) -> None:
    player = MovePlayer(ergo, _move(ergo), ramp_s=0.0)

    def broken(positions: object) -> None:
        raise RuntimeError("the goal would not go")

    monkeypatch.setattr(player, "_set_goals", broken)
    with caplog.at_level(logging.WARNING), pytest.raises(RuntimeError, match="would not go"):
        player.play()
    assert isinstance(player.error, RuntimeError) and not player.playing
    player.stop()
    player.stop()  # twice: nothing left to stop, nothing raised
    assert len(_failures(caplog, "move player")) == 1


def test_the_recorder_keeps_its_take_when_its_loop_fails(
    ergo: Robot, caplog: pytest.LogCaptureFixture, monkeypatch: pytest.MonkeyPatch
) -> None:
    recorder = MoveRecorder(ergo, freq=50.0)
    real = recorder._sample
    calls: list[float] = []

    def failing_later(now: float) -> None:
        calls.append(now)
        if len(calls) > 3:
            raise RuntimeError("the bus went away")
        real(now)

    monkeypatch.setattr(recorder, "_sample", failing_later)
    with caplog.at_level(logging.WARNING):
        recorder.start()
        assert eventually(lambda: not recorder.recording, timeout_s=10.0)
    assert isinstance(recorder.error, RuntimeError)
    move = recorder.stop()
    recorder.stop()  # twice is safe
    assert len(move.positions) >= 1
    assert len(_failures(caplog, "move recorder")) == 1
