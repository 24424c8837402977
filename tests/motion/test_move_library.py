"""``Move`` itself (interpolation, reversal, checks) and the move library folder."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from poppy_core.errors import ConfigError, UnknownMotorError
from poppy_core.motion import (
    Move,
    delete_move,
    export_move,
    import_move,
    is_move_name,
    list_moves,
    load_move,
    move_path,
    moves_dir,
    save_move,
)


@pytest.fixture(autouse=True)
def library(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    folder = tmp_path / "lib"
    monkeypatch.setenv("POPPY_MOVES_DIR", str(folder))
    return folder


def two_motor_move() -> Move:
    return Move(10, ["a", "b"], [[0.0, 10.0], [10.0, 20.0], [30.0, 20.0]])


def test_interpolation_between_frames_and_held_at_the_ends() -> None:
    move = two_motor_move()
    assert move.duration_s == pytest.approx(0.2) and len(move) == 3
    assert move.position_at(0.05) == pytest.approx({"a": 5.0, "b": 15.0})
    assert move.position_at(0.15) == pytest.approx({"a": 20.0, "b": 20.0})
    assert move.position_at(-1) == move.frame(0)
    assert move.position_at(9) == move.frame(-1)
    assert move.times().tolist() == pytest.approx([0.0, 0.1, 0.2])


def test_reversed_select_stats_and_from_frames() -> None:
    move = two_motor_move()
    back = move.reversed()
    assert back.trajectory("a").tolist() == [30.0, 10.0, 0.0]
    assert back.position_at(0.05)["a"] == pytest.approx(20.0)
    assert move.select(["b"]).motors == ("b",)
    assert move.stats()["a"] == {
        "min": 0.0,
        "max": 30.0,
        "range": 30.0,
        "mean": pytest.approx(40 / 3),
        "start": 0.0,
        "end": 30.0,
    }
    rebuilt = Move.from_frames(10, [move.frame(i) for i in range(3)])
    assert rebuilt.same_as(move)
    with pytest.raises(UnknownMotorError, match="c"):
        move.select(["c"])


@pytest.mark.parametrize(
    ("args", "match"),
    [
        ((0, ["a"], [[1.0]]), "framerate"),
        ((50, ["a", "a"], [[1.0, 2.0]]), "unique"),
        ((50, ["a"], [[1.0, 2.0]]), "shape"),
        ((50, ["a"], [[float("nan")]]), "finite"),
    ],
)
def test_bad_moves_are_refused(
    args: tuple[float, list[str], list[list[float]]], match: str
) -> None:
    with pytest.raises(ValueError, match=match):
        Move(*args)


def test_moves_dir_follows_the_environment(library: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    assert moves_dir() == library
    monkeypatch.delenv("POPPY_MOVES_DIR")
    assert moves_dir().parts[-2:] == ("poppy", "moves")


def test_save_list_load_delete(library: Path) -> None:
    assert list_moves() == []
    path = save_move(two_motor_move(), "wave")
    assert path == library / "wave.move"
    (library / "old.json").write_text(
        json.dumps({"framerate": 10, "positions": {"0.0": {"a": [1.0, 0.0]}}})
    )
    (library / "notes.txt").write_text("not a move")
    entries = list_moves()
    assert [(e.name, e.format) for e in entries] == [("old", "pypot"), ("wave", "poppy")]
    assert load_move("wave").same_as(two_motor_move())
    assert load_move("old").motors == ("a",)
    assert load_move(str(path)).same_as(two_motor_move())  # a path works as well
    assert move_path("old") == library / "old.json"
    assert delete_move("wave") == path and not path.exists()
    with pytest.raises(ConfigError, match=r"no move 'wave'.*old"):
        load_move("wave")
    with pytest.raises(ConfigError, match="not a move name"):
        save_move(two_motor_move(), "..")


def test_import_and_export(library: Path, tmp_path: Path) -> None:
    source = tmp_path / "from pypot.json"
    source.write_text(
        json.dumps({"framerate": 20, "positions": {"0.0": {"m1": [3, 0]}, "0.05": {"m1": [4, 0]}}})
    )
    target = import_move(source)
    assert target == library / "from pypot.move"
    assert load_move("from pypot").trajectory("m1").tolist() == [3.0, 4.0]
    assert load_move("from pypot").metadata["imported_from"] == str(source)
    with pytest.raises(ConfigError, match="exists"):
        import_move(source)
    import_move(source, "renamed")
    assert {e.name for e in list_moves()} == {"from pypot", "renamed"}

    as_pypot = export_move("renamed", tmp_path / "out.json")
    assert json.loads(as_pypot.read_text())["positions"]["0.05"]["m1"] == [4.0, 0.0]
    as_ours = export_move("renamed", tmp_path / "out.bin", "poppy")
    assert as_ours.read_bytes() == (library / "renamed.move").read_bytes()
    with pytest.raises(ConfigError, match="not a valid move"):
        import_move(_junk(tmp_path))
    assert np.array_equal(load_move(str(as_ours)).positions, [[3.0], [4.0]])


def _junk(folder: Path) -> Path:
    path = folder / "junk.move"
    path.write_bytes(b"\x00\x01 not a move")
    return path


def test_the_library_lists_only_the_moves_a_name_can_reach(library: Path) -> None:
    save_move(two_motor_move(), "my wave.v2")
    (library / "wave (copy).move").write_bytes((library / "my wave.v2.move").read_bytes())
    assert [e.name for e in list_moves()] == ["my wave.v2"]
    assert is_move_name("my wave.v2") and not is_move_name("wave (copy)")
    assert not is_move_name(".hidden") and not is_move_name("a/b") and not is_move_name("x.")
