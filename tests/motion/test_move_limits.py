"""Moves are bounded at load (rate, frames, positions) and clamped to the limits before a ramp."""

from __future__ import annotations

import contextlib
import json
import struct
import tracemalloc
from pathlib import Path

import numpy as np
import pytest

from poppy_core.errors import ArgumentError, ConfigError
from poppy_core.motion import Move, MovePlayer, read_move
from poppy_core.motion.move import MAX_VALUES
from poppy_core.motion.move_format import MAGIC, decode_move, decode_pypot
from poppy_core.robot import Robot
from tests.helpers.fixtures import ergo_fixture

# The 103-byte pypot move: two frames 1e5 s apart at 1e6 Hz (1e11 frames once resampled).
SPARSE = json.dumps(
    {"framerate": 1e6, "positions": {"0.0": {"m1": [0, 0]}, "100000.0": {"m1": [1, 0]}}}
)


def _peak(work: object) -> int:
    tracemalloc.start()
    try:
        with contextlib.suppress(ConfigError):
            work()  # type: ignore[operator]
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def test_a_sparse_pypot_move_at_a_huge_rate_is_refused_before_any_allocation() -> None:
    assert len(SPARSE) < 110
    with pytest.raises(ConfigError, match=r"framerate must be 0.1-1000 Hz"):
        decode_pypot(SPARSE, "x.json")
    assert _peak(lambda: decode_pypot(SPARSE, "x.json")) < 1_000_000
    slower = SPARSE.replace("1000000.0", "1000.0")
    with pytest.raises(ConfigError, match="at most 5,000,000 values"):
        decode_pypot(slower, "x.json")
    assert _peak(lambda: decode_pypot(slower, "x.json")) < 1_000_000


@pytest.mark.parametrize("framerate", [1e-300, 0.01, 1e308, -5])
def test_framerates_out_of_range_are_refused(framerate: float) -> None:
    document = json.dumps({"framerate": framerate, "positions": {"0": {"m1": [0, 0]}}})
    with pytest.raises(ConfigError, match=r"x.json: not a valid move file: framerate"):
        decode_pypot(document, "x.json")


@pytest.mark.parametrize("position", [1e6, -2000, 1e308])
def test_positions_out_of_any_servo_range_are_refused(position: float) -> None:
    document = json.dumps({"framerate": 50, "positions": {"0": {"m1": [position, 0]}}})
    with pytest.raises(ConfigError, match="positions must be within ±1000"):
        decode_pypot(document, "x.json")


def test_a_binary_header_cannot_announce_a_huge_move() -> None:
    header = json.dumps(
        {
            "format": "poppy-move",
            "version": 1,
            "framerate": 50,
            "motors": ["m1"],
            "frames": 10**12,
            "dtype": "<f4",
        }
    ).encode()
    data = MAGIC + struct.pack("<I", len(header)) + header
    with pytest.raises(ConfigError, match="at most 5,000,000 values"):
        decode_move(data, "x.move")
    with pytest.raises(ConfigError, match="header"):
        decode_move(MAGIC + struct.pack("<I", 2**32 - 1) + b"{}", "x.move")


def test_moves_built_in_python_are_bounded_too() -> None:
    with pytest.raises(ArgumentError, match="framerate"):
        Move(1e-300, ["m1"], [[0.0]])
    with pytest.raises(ArgumentError, match="at most"):
        Move(50, [f"m{i}" for i in range(2)], np.zeros((MAX_VALUES // 2 + 1, 2)))


def test_deep_or_huge_pypot_json_is_one_error(tmp_path: Path) -> None:
    path = tmp_path / "deep.json"
    path.write_text('{"framerate": 50, "positions": ' + "[" * 100_000 + "]" * 100_000 + "}")
    with pytest.raises(ConfigError, match=r"deep.json: not a valid move file: nested"):
        read_move(path)
    path.write_text('{"framerate": 5' + "0" * 5000 + ', "positions": {}}')
    with pytest.raises(ConfigError, match=r"deep.json: not a valid move file"):
        read_move(path)


ergo = ergo_fixture(scope="module")


def test_positions_past_the_limits_are_clamped_before_the_ramp(ergo: Robot) -> None:
    low, high = ergo.m1.angle_limit
    move = Move(50, ["m1", "m2"], [[900.0, 0.0], [-900.0, 0.0], [0.0, 0.0]])
    player = MovePlayer(ergo, move)
    assert player.clamped == {"m1": pytest.approx(max(900.0 - high, low + 900.0))}
    played = player.played.trajectory("m1")
    assert played.tolist() == [high, low, 0.0]
    assert player.played.trajectory("m2").tolist() == [0.0, 0.0, 0.0]
    backwards = MovePlayer(ergo, move, backwards=True)
    assert backwards.played.trajectory("m1").tolist() == [0.0, low, high]


def test_noise_at_a_limit_is_not_reported(ergo: Robot) -> None:
    _, high = ergo.m1.angle_limit
    assert MovePlayer(ergo, Move(50, ["m1"], [[high + 0.2]])).clamped == {}
