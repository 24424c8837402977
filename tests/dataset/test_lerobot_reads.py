"""LeRobot 0.4.4's own code (in bench/.venv-lerobot) reads what poppy writes, and writes the same.

Each test records with poppy_core.dataset here, then asks tests/dataset/lerobot_oracle.py, one
process in LeRobot's venv for the module (fails on CI without it, skips elsewhere:
tests/helpers/lerobot_venv.py).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest

from poppy_core.dataset.delete import delete_episode
from poppy_core.dataset.writer import DatasetWriter
from tests.dataset.test_writer import SPEC, frame, killed_recording, record
from tests.helpers.json_lines import JsonChild
from tests.helpers.lerobot_venv import oracle_fixture

pytestmark = pytest.mark.slow


oracle = oracle_fixture()


def test_lerobot_loads_and_decodes_a_poppy_recording(oracle: JsonChild, tmp_path: Path) -> None:
    root = tmp_path / "ds"
    record(root, [20, 25], ["pick the cube", "wave"])
    seen = oracle.ask("load", str(root), "poppy/test", "0,19,20,21,44")
    assert (seen["len"], seen["num_episodes"], seen["fps"]) == (45, 2, 30)
    info = json.loads((root / "meta/info.json").read_text())
    assert seen["features"] == info["features"]
    assert seen["tasks"] == ["pick the cube", "wave"]
    # frames come back at their places, camera frames decoded at their timestamps k/fps
    places = [(0, 0), (0, 19), (1, 0), (1, 1), (1, 24)]
    for item, (episode, k) in zip(seen["items"], places, strict=True):
        state, action, images = frame(k)
        assert (item["episode_index"], item["frame_index"]) == (episode, k)
        assert item["timestamp"] == pytest.approx(k / 30)
        assert item["observation.state"] == pytest.approx(state)
        assert item["action"] == pytest.approx(action)
        assert item["task"] == ["pick the cube", "wave"][episode]
        picture = item["observation.images.top"]
        assert picture["shape"] == [3, 48, 64]
        assert picture["pixel"] == pytest.approx(images["top"][24, 32].tolist(), abs=6)
    assert seen["stats"] == json.loads((root / "meta/stats.json").read_text())


def test_stats_agree_with_lerobots_own_computation(oracle: JsonChild, tmp_path: Path) -> None:
    root = tmp_path / "ds"
    record(root, [30, 17])
    seen = oracle.ask("load", str(root), "poppy/test")
    mine, theirs = seen["stats"], seen["recomputed_stats"]
    for key, feature in theirs.items():
        assert set(mine[key]) == set(feature), key
        for name in ("min", "max", "mean", "std", "count"):
            assert mine[key][name] == pytest.approx(feature[name]), (key, name)
        # LeRobot estimates quantiles from a 5000-bin histogram, poppy takes numpy's exact ones:
        # two estimates of one quantile, within 5 % of the feature's range
        spread = np.asarray(feature["max"], float) - np.asarray(feature["min"], float)
        for name in ("q01", "q10", "q50", "q90", "q99"):
            gap = np.abs(np.asarray(mine[key][name]) - np.asarray(feature[name]))
            assert np.all(gap <= 0.05 * spread + 1e-9), (key, name, gap)


def test_info_and_tables_match_what_lerobot_writes(oracle: JsonChild, tmp_path: Path) -> None:
    ours = tmp_path / "poppy"
    # the frames lerobot_oracle.py's `write` adds: every value k, every pixel k
    with DatasetWriter.create(ours, SPEC) as writer:
        writer.begin_episode("pick the cube")
        for k in range(5):
            writer.add_frame([k] * 3, [k] * 3, {"top": np.full((48, 64, 3), k, np.uint8)})
        writer.save_episode()
    info = json.loads((ours / "meta/info.json").read_text())
    features = {
        key: {name: value for name, value in ft.items() if name not in ("info", "unit")}
        for key, ft in info["features"].items()
    }
    spec = {"fps": 30, "robot_type": info["robot_type"], "features": features, "frames": 5}
    theirs = tmp_path / "lerobot"
    lerobot_info = oracle.ask("write", str(theirs), json.dumps(spec))
    assert list(info) == list(lerobot_info)
    for key, value in lerobot_info.items():
        if key != "features":
            assert info[key] == value, key
    assert list(info["features"]) == list(lerobot_info["features"])
    for key, feature in lerobot_info["features"].items():
        # poppy's one addition: the joints' unit (degrees)
        mine = {name: value for name, value in info["features"][key].items() if name != "unit"}
        assert mine == feature, key
    assert info["features"]["action"]["unit"] == "degree"
    for table in (
        "data/chunk-000/file-000.parquet",
        "meta/episodes/chunk-000/file-000.parquet",
        "meta/tasks.parquet",
    ):
        mine_schema = pq.read_schema(ours / table)
        their_schema = pq.read_schema(theirs / table)
        assert sorted(mine_schema.names) == sorted(their_schema.names), table
        for name in their_schema.names:
            mine_type, their_type = mine_schema.field(name).type, their_schema.field(name).type
            assert str(mine_type).replace("large_", "") == str(their_type).replace("large_", ""), (
                table,
                name,
            )
    mine_stats = json.loads((ours / "meta/stats.json").read_text())
    their_stats = json.loads((theirs / "meta/stats.json").read_text())
    assert {k: sorted(v) for k, v in mine_stats.items()} == {
        k: sorted(v) for k, v in their_stats.items()
    }
    for key in mine_stats:
        for name in ("min", "max", "mean", "std", "count"):
            mine_value, their_value = mine_stats[key][name], their_stats[key][name]
            np.testing.assert_allclose(mine_value, their_value, err_msg=f"{key} {name}")


def test_lerobot_loads_a_killed_recording(oracle: JsonChild, tmp_path: Path) -> None:
    root = tmp_path / "ds"
    killed_recording(root)
    seen = oracle.ask("load", str(root), "poppy/test", "0,20")
    assert (seen["len"], seen["num_episodes"]) == (21, 2)
    assert [(i["episode_index"], i["frame_index"]) for i in seen["items"]] == [(0, 0), (1, 8)]
    assert SPEC.video_keys() == ["observation.images.top"]


def test_lerobot_loads_a_dataset_after_an_episode_is_deleted(
    oracle: JsonChild, tmp_path: Path
) -> None:
    root = tmp_path / "ds"
    record(root, [20, 25, 15], ["pick the cube", "wave", "pick the cube"])
    delete_episode(root, 1)
    seen = oracle.ask("load", str(root), "poppy/test", "0,19,20,34")
    assert (seen["len"], seen["num_episodes"]) == (35, 2)
    assert seen["tasks"] == ["pick the cube"]
    assert seen["stats"] == json.loads((root / "meta/stats.json").read_text())
    places = [(0, 0), (0, 19), (1, 0), (1, 14)]
    for item, (episode, k) in zip(seen["items"], places, strict=True):
        state, action, images = frame(k)
        assert (item["episode_index"], item["frame_index"], item["index"]) == (
            episode,
            k,
            20 * episode + k,
        )
        assert item["action"] == pytest.approx(action) and item["task"] == "pick the cube"
        assert item["observation.state"] == pytest.approx(state)
        # the moved video decodes at its new place
        assert item["observation.images.top"]["pixel"] == pytest.approx(
            images["top"][24, 32].tolist(), abs=6
        )
    for key, feature in seen["recomputed_stats"].items():
        for name in ("min", "max", "mean", "std", "count"):
            assert seen["stats"][key][name] == pytest.approx(feature[name]), (key, name)


def test_an_episode_is_deleted_from_a_dataset_lerobot_packed(
    oracle: JsonChild, tmp_path: Path
) -> None:
    root = tmp_path / "lerobot"
    features = {
        "observation.state": {"dtype": "float32", "shape": [3], "names": ["a", "b", "c"]},
        "action": {"dtype": "float32", "shape": [3], "names": ["a", "b", "c"]},
        "observation.images.top": {
            "dtype": "video",
            "shape": [48, 64, 3],
            "names": ["height", "width", "channels"],
        },
    }
    spec = {
        "fps": 30,
        "robot_type": "ergo-jr",
        "features": features,
        "episodes": [12, 10, 8],
        "tasks": ["pick", "wave", "pick"],
    }
    oracle.ask("write", str(root), json.dumps(spec))
    assert sorted(p.name for p in (root / "data/chunk-000").iterdir()) == ["file-000.parquet"]
    done = delete_episode(root, 1)
    assert (done.frames, done.episodes_left, done.frames_left, done.tasks_left) == (10, 2, 20, 1)
    seen = oracle.ask("load", str(root), "poppy/oracle", "0,11,12,19")
    assert (seen["len"], seen["num_episodes"], seen["tasks"]) == (20, 2, ["pick"])
    places = [(0, 0, 0), (0, 11, 11), (1, 0, 80), (1, 7, 87)]  # episode 2's values: k + 80
    for item, (episode, k, value) in zip(seen["items"], places, strict=True):
        assert (item["episode_index"], item["frame_index"]) == (episode, k)
        assert item["index"] == 12 * episode + k and item["task_index"] == 0
        assert item["action"] == pytest.approx([value] * 3)
        # the video is the same file: the episode left decodes at its own span
        assert item["observation.images.top"]["pixel"] == pytest.approx([value] * 3, abs=6)
    for key, feature in seen["recomputed_stats"].items():
        for name in ("min", "max", "mean", "std", "count"):
            assert seen["stats"][key][name] == pytest.approx(feature[name]), (key, name)
