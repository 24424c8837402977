"""poppy_core.dataset.delete: an episode removed, the rest renumbered, as if never recorded."""

from __future__ import annotations

import errno
import json
import os
import re
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest

from poppy_core.dataset import delete as delete_module
from poppy_core.dataset.delete import delete_episode
from poppy_core.errors import ArgumentError
from tests.dataset.test_writer import record

TABLES = ("meta/tasks.parquet", "meta/episodes/chunk-000/file-000.parquet")
VIDEO = "videos/observation.images.top/chunk-000/file-{:03d}.mp4"


def snapshot(root: Path) -> dict[str, bytes]:
    """Every file of a dataset, by path (hidden ones too)."""
    return {
        str(path.relative_to(root)): path.read_bytes()
        for path in sorted(root.rglob("*"))
        if path.is_file()
    }


def without_stats(rows: list[dict]) -> list[dict]:
    return [{k: v for k, v in row.items() if not k.startswith("stats/")} for row in rows]


def test_deleting_is_recording_without_that_episode(tmp_path: Path) -> None:
    root, fresh = tmp_path / "ds", tmp_path / "fresh"
    record(root, [20, 25, 15, 10], ["pick the cube", "wave", "pick the cube", "point"])
    # the same frames (frame k of every episode is the same), the deleted episode never recorded
    record(fresh, [20, 15, 10], ["pick the cube", "pick the cube", "point"])
    old = snapshot(root)
    done = delete_episode(root, 1)
    assert (done.episode, done.frames) == (1, 25)
    assert (done.episodes_left, done.frames_left, done.tasks_left) == (3, 45, 2)
    now = snapshot(root)
    assert sorted(now) == sorted(snapshot(fresh))  # the same files, no leftover
    for name in (
        "data/chunk-000/file-000.parquet",
        "data/chunk-000/file-001.parquet",
        "data/chunk-000/file-002.parquet",
        *TABLES,
    ):
        assert pq.read_table(root / name).to_pylist() == pq.read_table(fresh / name).to_pylist()
    data = pq.read_table(root / "data/chunk-000/file-001.parquet").to_pydict()
    assert data["episode_index"] == [1] * 15 and data["index"] == list(range(20, 35))
    assert data["task_index"] == [0] * 15
    assert (
        pq.read_table(root / "data/chunk-000/file-002.parquet")["task_index"].to_pylist()
        == [1] * 10
    )
    rows = pq.read_table(root / TABLES[1]).to_pylist()
    assert [(r["episode_index"], r["dataset_from_index"], r["length"]) for r in rows] == [
        (0, 0, 20),
        (1, 20, 15),
        (2, 35, 10),
    ]
    assert rows == pq.read_table(fresh / TABLES[1]).to_pylist()  # episode stats too
    assert json.loads((root / "meta/info.json").read_text()) == json.loads(
        (fresh / "meta/info.json").read_text()
    )
    ours = json.loads((root / "meta/stats.json").read_text())
    theirs = json.loads((fresh / "meta/stats.json").read_text())
    assert ours.keys() == theirs.keys()
    for key in ours:
        for name in ours[key]:
            assert np.ravel(ours[key][name]) == pytest.approx(np.ravel(theirs[key][name])), key
    # the videos moved one place down, untouched
    assert now[VIDEO.format(1)] == old[VIDEO.format(2)]
    assert now[VIDEO.format(2)] == old[VIDEO.format(3)]
    assert not list(tmp_path.glob(".ds.*"))


def test_deleting_the_last_and_the_first_episodes(tmp_path: Path) -> None:
    root = tmp_path / "ds"
    record(root, [20, 25, 15])
    delete_episode(root, 2)
    assert not (root / VIDEO.format(2)).exists()
    assert json.loads((root / "meta/info.json").read_text())["total_frames"] == 45
    delete_episode(root, 0)
    data = pq.read_table(root / "data/chunk-000/file-000.parquet").to_pydict()
    assert data["episode_index"] == [0] * 25 and data["index"] == list(range(25))
    info = json.loads((root / "meta/info.json").read_text())
    assert (info["total_episodes"], info["total_frames"], info["splits"]) == (
        1,
        25,
        {"train": "0:1"},
    )


@pytest.mark.parametrize(
    ("lengths", "episode", "message"),
    [
        ([20, 25], 2, "no episode 2 in this dataset (episodes: 0 to 1)"),
        ([20], 0, "is the only one: delete the folder"),
    ],
)
def test_bad_episodes_are_refused_and_nothing_changes(
    tmp_path: Path, lengths: list[int], episode: int, message: str
) -> None:
    root = tmp_path / "ds"
    record(root, lengths)
    before = snapshot(root)
    with pytest.raises(ArgumentError, match=re.escape(message)):
        delete_episode(root, episode)
    assert snapshot(root) == before


def test_an_interrupted_deletion_leaves_the_dataset_as_it_was(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    root = tmp_path / "ds"
    record(root, [20, 25, 15], ["a", "b", "c"])
    before = snapshot(root)

    def interrupted(new: Path, old: Path) -> None:
        assert (new / "meta/info.json").is_file()  # the new dataset was whole, not swapped in
        raise KeyboardInterrupt

    monkeypatch.setattr(delete_module, "_swap", interrupted)
    with pytest.raises(KeyboardInterrupt):
        delete_episode(root, 0)
    assert snapshot(root) == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ds"]
    # a folder left by a killed deletion is removed by the next one
    (tmp_path / ".ds.delete-999999").mkdir()
    monkeypatch.undo()
    delete_episode(root, 0)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ds"]
    assert json.loads((root / "meta/info.json").read_text())["total_tasks"] == 2


def test_the_swap_without_renameat2(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(delete_module, "_exchange", lambda a, b: False)
    root = tmp_path / "ds"
    record(root, [20, 25])
    delete_episode(root, 0)
    assert json.loads((root / "meta/info.json").read_text())["total_frames"] == 25
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ds"]


def test_a_failed_fallback_swap_puts_the_dataset_back(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    root = tmp_path / "ds"
    record(root, [20, 25])
    before = snapshot(root)
    rename = os.rename

    def failing(source: Path, target: Path) -> None:
        if ".delete-" in Path(source).name:
            raise OSError(errno.EXDEV, "simulated")
        rename(source, target)

    monkeypatch.setattr(delete_module, "_exchange", lambda a, b: False)
    monkeypatch.setattr(delete_module.os, "rename", failing)
    with pytest.raises(OSError, match="simulated"):
        delete_episode(root, 0)
    monkeypatch.undo()
    assert snapshot(root) == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ds"]
