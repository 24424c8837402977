"""A take is never lost to its destination: checked first, kept in memory, saved elsewhere."""

from __future__ import annotations

import errno
import logging
import time
from pathlib import Path

import pytest

from poppy_core.errors import ConfigError, FileError
from poppy_core.motion import MoveRecorder, read_move
from poppy_core.motion import recorder as recorder_module
from poppy_core.robot import Robot
from tests.helpers.fixtures import ergo_fixture

ergo = ergo_fixture(scope="module")


def _wait_frames(recorder: MoveRecorder, count: int) -> None:
    deadline = time.monotonic() + 10
    while recorder.frames_recorded < count and time.monotonic() < deadline:
        time.sleep(0.02)


def test_a_missing_folder_is_refused_before_recording(ergo: Robot, tmp_path: Path) -> None:
    recorder = MoveRecorder(ergo, 50, ["m1"], checkpoint_path=tmp_path / "no" / "w.move")
    with pytest.raises(FileError, match="does not exist"):
        recorder.start()
    assert not recorder.recording and recorder.frames_recorded == 0


def test_a_failing_destination_keeps_the_take(
    ergo: Robot, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    real_write = recorder_module.write_move

    def full(*args: object, **kwargs: object) -> Path:
        raise FileError("cannot write w.move: no space left on the device", errno=errno.ENOSPC)

    monkeypatch.setattr(recorder_module, "write_move", full)
    target = tmp_path / "w.move"
    recorder = MoveRecorder(
        ergo, 50, ["m1", "m2"], checkpoint_path=target, checkpoint_period_s=0.02
    )
    with caplog.at_level(logging.WARNING, logger="poppy_core.motion.recorder"):
        recorder.start()
        _wait_frames(recorder, 30)
        with pytest.raises(FileError, match="no space left"):
            recorder.stop()
    failures = [r for r in caplog.records if "failed" in r.getMessage()]
    assert len(failures) == 1  # once, not at every checkpoint
    assert recorder.checkpoint_error is not None
    assert len(recorder.move) >= 25  # still held
    monkeypatch.setattr(recorder_module, "write_move", real_write)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    saved = recorder.save(elsewhere)
    assert saved == elsewhere / "w.move"
    assert read_move(saved).same_as(recorder.move, tolerance_deg=1e-3)
    assert not (tmp_path / ".w.move.lock").exists()
    assert recorder.save() == target  # and again where it was meant to go, now it works


def test_a_checkpoint_that_works_again_is_said_once(
    ergo: Robot, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    real_write = recorder_module.write_move
    failing = {"on": True}

    def flaky(*args: object, **kwargs: object) -> Path:
        if failing["on"]:
            raise FileError("cannot write: no space left on the device", errno=errno.ENOSPC)
        return real_write(*args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(recorder_module, "write_move", flaky)
    recorder = MoveRecorder(
        ergo, 50, ["m1"], checkpoint_path=tmp_path / "w.move", checkpoint_period_s=0.02
    )
    with caplog.at_level(logging.WARNING, logger="poppy_core.motion.recorder"):
        recorder.start()
        _wait_frames(recorder, 10)
        failing["on"] = False
        _wait_frames(recorder, 30)
        move = recorder.stop()
    messages = [r.getMessage() for r in caplog.records]
    assert sum("failed" in m for m in messages) == 1
    assert sum("works again" in m for m in messages) == 1
    assert read_move(tmp_path / "w.move").same_as(move, tolerance_deg=1e-3)


def test_two_recorders_cannot_write_one_file(ergo: Robot, tmp_path: Path) -> None:
    first = MoveRecorder(ergo, 50, ["m1"], checkpoint_path=tmp_path / "same.move").start()
    second = MoveRecorder(ergo, 50, ["m2"], checkpoint_path=tmp_path / "same.move")
    try:
        with pytest.raises(FileError, match=r"another poppy process .* is writing"):
            second.start()
        assert not second.recording
    finally:
        first.stop()
    second.start()  # free once the first one is done
    second.stop()


def test_an_existing_file_is_not_replaced_unless_asked(ergo: Robot, tmp_path: Path) -> None:
    target = tmp_path / "mine.move"
    target.write_bytes(b"not a take")
    recorder = MoveRecorder(
        ergo, 50, ["m1"], checkpoint_path=target, replace=False, checkpoint_period_s=0.02
    )
    recorder.start()
    _wait_frames(recorder, 10)
    with pytest.raises(FileError, match="already exists"):
        recorder.stop()
    assert target.read_bytes() == b"not a take"
    assert len(recorder.move) > 0


def test_a_motor_name_alone_is_one_motor(ergo: Robot) -> None:
    assert [m.name for m in MoveRecorder(ergo, 50, "m2").motors] == ["m2"]
    with pytest.raises(ConfigError, match="no motor or group 'head_z'"):
        MoveRecorder(ergo, 50, "head_z")
