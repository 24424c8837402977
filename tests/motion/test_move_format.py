"""Move codecs: poppy's binary format and pypot's JSON, round trips, corruption, atomic writes."""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from poppy_core.errors import ConfigError, FileError
from poppy_core.motion import (
    Move,
    decode_any,
    decode_move,
    decode_pypot,
    encode_move,
    encode_pypot,
    read_move,
    write_move,
)

names = st.lists(
    st.text(st.characters(codec="utf-8", exclude_categories=["Cs"]), min_size=1, max_size=8),
    min_size=1,
    max_size=5,
    unique=True,
)
angles = st.floats(-1000.0, 1000.0, allow_nan=False, allow_infinity=False)
rates = st.sampled_from([1.0, 10.0, 25.0, 30.0, 50.0, 100.0, 1000.0 / 3])


@st.composite
def moves(draw: st.DrawFn, speeds: bool | None = None) -> Move:
    motors = draw(names)
    count = draw(st.integers(0, 30))
    values = draw(st.lists(angles, min_size=count * len(motors), max_size=count * len(motors)))
    positions = np.array(values, dtype=np.float64).reshape(count, len(motors))
    with_speeds = draw(st.booleans()) if speeds is None else speeds
    metadata = draw(st.dictionaries(st.sampled_from(["robot", "created", "note"]), st.text()))
    return Move(
        draw(rates),
        motors,
        positions,
        speeds=-positions if with_speeds else None,
        metadata=metadata,
    )


@settings(max_examples=150, deadline=None)
@given(moves())
def test_poppy_format_round_trip(move: Move) -> None:
    back = decode_move(encode_move(move))
    assert back.motors == move.motors and back.framerate == move.framerate
    assert back.metadata == move.metadata
    # float32 on disk: relative precision 2**-24
    assert np.allclose(back.positions, move.positions, rtol=2**-23, atol=1e-30)
    assert (back.speeds is None) == (move.speeds is None)
    assert encode_move(back) == encode_move(move)  # stable once in float32
    exact = decode_move(encode_move(move, dtype="<f8"))
    assert np.array_equal(exact.positions, move.positions)


@settings(max_examples=100, deadline=None)
@given(moves())
def test_pypot_json_round_trip(move: Move) -> None:
    data = encode_pypot(move)
    document = json.loads(data)
    assert set(document) == {"framerate", "positions"}
    if len(move):
        first = document["positions"]["0.0"]
        assert list(first) == list(move.motors)
        assert all(isinstance(v, list) and len(v) == 2 for v in first.values())
    back = decode_pypot(data)
    assert back.framerate == move.framerate
    if len(move):
        assert back.motors == move.motors
        assert np.array_equal(back.positions, move.positions)  # JSON floats are exact
        assert back.speeds is not None
        if move.speeds is not None:
            assert np.array_equal(back.speeds, move.speeds)
    assert decode_any(data).same_as(back)


@settings(max_examples=200, deadline=None)
@given(st.binary(max_size=200))
def test_garbage_is_a_config_error(data: bytes) -> None:
    try:
        decode_any(data, "junk.bin")
    except ConfigError as exc:
        assert exc.file == "junk.bin"


@settings(max_examples=100, deadline=None)
@given(moves(), st.data())
def test_truncated_poppy_file_is_refused(move: Move, data: st.DataObject) -> None:
    encoded = encode_move(move)
    cut = data.draw(st.integers(0, len(encoded) - 1))
    with pytest.raises(ConfigError, match="not a valid move file"):
        decode_move(encoded[:cut])


def pypot_document(times: list[float]) -> str:
    return json.dumps(
        {
            "framerate": 50.0,
            "positions": {repr(t): {"m1": [100 * t, 0.0], "m2": [-t, 1.0]} for t in times},
        }
    )


def test_pypot_times_with_jitter_are_sorted_and_kept() -> None:
    # Keys as pypot's recorder writes them: elapsed times, out of order, with a little jitter.
    move = decode_pypot(pypot_document([0.013, 0.05, 0.031, 0.093, 0.071]))
    assert move.motors == ("m1", "m2")
    assert move.trajectory("m1").tolist() == pytest.approx([1.3, 3.1, 5.0, 7.1, 9.3])


def test_pypot_irregular_times_are_resampled() -> None:
    # A missed frame (no 0.08): more than half a period off the grid, so resampled.
    move = decode_pypot(pypot_document([0.0, 0.1, 0.02, 0.04, 0.06]))
    assert len(move) == 6 and move.duration_s == pytest.approx(0.1)
    assert np.allclose(move.trajectory("m1"), 100 * move.times())


def test_pypot_motor_missing_from_some_frames_is_filled() -> None:
    document = {
        "framerate": 10,
        "positions": {"0.0": {"m1": [1, 0]}, "0.1": {"m1": [2, 0], "m2": [5, 0]}, "0.2": {"m2": 7}},
    }
    move = decode_pypot(json.dumps(document))
    assert move.motors == ("m1", "m2")
    assert move.trajectory("m1").tolist() == [1, 2, 2]
    assert move.trajectory("m2").tolist() == [5, 5, 7]


@pytest.mark.parametrize(
    "text",
    [
        "[]",
        '{"framerate": 50}',
        '{"framerate": 0, "positions": {}}',
        '{"framerate": 50, "positions": {"zero": {}}}',
        '{"framerate": 50, "positions": {"0.0": {"m1": "up"}}}',
        '{"framerate": 50, "positions": {"0.0": {"m1": [NaN, 0]}}}',
    ],
)
def test_bad_pypot_json_is_a_config_error(text: str) -> None:
    with pytest.raises(ConfigError, match=r"old\.json"):
        decode_pypot(text, "old.json")


def test_newer_format_version_is_refused() -> None:
    data = encode_move(Move(50, ["m1"], [[1.0]]))
    newer = data.replace(b'"version":1', b'"version":9')
    with pytest.raises(ConfigError, match="version 9"):
        decode_move(newer)


def test_files_by_suffix(tmp_path: Path) -> None:
    move = Move(25, ["a", "b"], [[1.0, 2.0], [3.0, 4.0]])
    with pytest.raises(FileError, match="does not exist: create it first"):
        write_move(move, tmp_path / "sub" / "x.move")
    ours = write_move(move, tmp_path / "sub" / "x.move", make_folder=True)
    theirs = write_move(move, tmp_path / "x.json")
    assert ours.read_bytes().startswith(b"POPPYMOV")
    assert json.loads(theirs.read_text())["framerate"] == 25
    assert read_move(ours).same_as(move) and read_move(theirs).same_as(move)
    with pytest.raises(ConfigError, match="cannot read"):
        read_move(tmp_path / "missing.move")


def test_failed_write_leaves_the_old_file(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    path = tmp_path / "keep.move"
    old = Move(50, ["m1"], [[1.0], [2.0]])
    write_move(old, path)
    before = path.read_bytes()

    def broken_fsync(fd: int) -> None:
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(os, "fsync", broken_fsync)
    with pytest.raises(FileError, match="no space left on the device"):
        write_move(Move(50, ["m1"], np.zeros((500, 1))), path)
    monkeypatch.undo()
    assert path.read_bytes() == before
    assert read_move(path).same_as(old)
    assert os.listdir(tmp_path) == ["keep.move"]  # no temporary file left behind


def test_ten_minute_move_is_compact(tmp_path: Path) -> None:
    frames = 30_000
    positions = np.sin(np.linspace(0, 60, frames))[:, None] * np.arange(1, 26)[None, :]
    move = Move(50, [f"m{i}" for i in range(25)], positions)
    path = write_move(move, tmp_path / "long.move")
    assert path.stat().st_size < frames * 25 * 4 + 1024  # float32 frames + a small header
    assert read_move(path).same_as(move, tolerance_deg=1e-4)
