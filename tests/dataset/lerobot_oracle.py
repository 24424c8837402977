"""Run inside bench/.venv-lerobot (LeRobot 0.4.4): what LeRobot's own code makes of a dataset.

``python lerobot_oracle.py load ROOT REPO_ID FRAMES``: LeRobotDataset(REPO_ID, root=ROOT), its
length, features, stats, the frames asked for (decoded at their timestamps by LeRobot's
default decoder), and the stats LeRobot's ``compute_episode_stats``/``aggregate_stats``
compute from the frames it loaded. ``python lerobot_oracle.py write ROOT SPEC``: the dataset
LeRobot's ``create/add_frame/save_episode/finalize`` write for the same features (SPEC: JSON of
fps, robot_type, features, frames; or ``episodes``, their lengths, and their ``tasks``: frame k
of episode e holds k + 40 e everywhere, LeRobot packing the episodes into one file). One JSON
object on stdout. ``python lerobot_oracle.py serve``: the same commands, asked one JSON line
each on stdin (tests/helpers/json_lines.py), in one process for a whole test module.
"""

from __future__ import annotations

import json
import sys
from functools import partial

import numpy as np


def as_lists(value):
    if isinstance(value, dict):
        return {key: as_lists(inner) for key, inner in value.items()}
    if hasattr(value, "tolist"):
        return value.tolist()
    return value


def load(root: str, repo_id: str, frames: list[int]) -> dict:
    from lerobot.datasets.compute_stats import aggregate_stats, compute_episode_stats
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    dataset = LeRobotDataset(repo_id, root=root)
    items = []
    for index in frames:
        item = dataset[index]
        entry = {"task": item["task"]}
        for key, value in item.items():
            if key.startswith("observation.images."):
                # (C, H, W) floats in [0, 1]: the pixel the tests draw, back to 0-255
                entry[key] = {
                    "shape": list(value.shape),
                    "pixel": (value[:, 24, 32] * 255).round().tolist(),
                }
            elif key != "task":
                entry[key] = value.tolist()
        items.append(entry)
    table = dataset.hf_dataset.with_format("numpy")
    features = {
        key: ft for key, ft in dataset.features.items() if ft["dtype"] not in ("video", "image")
    }
    per_episode = []
    episode_column = np.asarray(table["episode_index"])
    for episode in range(dataset.meta.total_episodes):
        rows = np.nonzero(episode_column == episode)[0]
        data = {key: np.stack([np.asarray(table[int(i)][key]) for i in rows]) for key in features}
        per_episode.append(compute_episode_stats(data, features))
    recomputed = aggregate_stats(per_episode)
    return {
        "len": len(dataset),
        "num_episodes": dataset.num_episodes,
        "fps": dataset.fps,
        "features": as_lists(dataset.features),
        "stats": as_lists(dataset.meta.stats),
        "recomputed_stats": as_lists(recomputed),
        "tasks": list(dataset.meta.tasks.index),
        "items": items,
        "video_backend": dataset.video_backend,
    }


def write(root: str, spec: dict) -> dict:
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    features = {
        key: {**ft, "shape": tuple(ft["shape"])}
        for key, ft in spec["features"].items()
        if key not in ("timestamp", "frame_index", "episode_index", "index", "task_index")
    }
    dataset = LeRobotDataset.create(
        "poppy/oracle", spec["fps"], features, root=root, robot_type=spec["robot_type"]
    )
    lengths = spec.get("episodes") or [spec["frames"]]
    tasks = spec.get("tasks") or ["pick the cube"] * len(lengths)
    for episode, length in enumerate(lengths):
        for k in range(length):
            frame = {"task": tasks[episode]}
            value = k + 40 * episode  # episode 0: every value k, every pixel k
            for key, ft in features.items():
                if ft["dtype"] == "video":
                    frame[key] = np.full(ft["shape"], value % 256, dtype=np.uint8)
                else:
                    frame[key] = np.full(ft["shape"], float(value), dtype=np.float32)
            dataset.add_frame(frame)
        dataset.save_episode()
    dataset.finalize()
    with open(f"{root}/meta/info.json", encoding="utf-8") as file:
        return json.load(file)


def command(name: str, root: str, argument: str, frames: str = "") -> dict:
    """One command, its arguments as on the command line."""
    if name == "load":
        return load(root, argument, [int(i) for i in frames.split(",")] if frames else [])
    assert name == "write", name
    return write(root, json.loads(argument))


def warm() -> None:
    """LeRobot's dataset modules imported (torch...): most of a command's CPU."""
    import lerobot.datasets.compute_stats
    import lerobot.datasets.lerobot_dataset  # noqa: F401


def load_serve():
    """tests/helpers/json_lines.py's ``serve``, loaded by its path (the venv has a ``tests``)."""
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "helpers" / "json_lines.py"
    spec = importlib.util.spec_from_file_location("poppy_json_lines", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.serve


if __name__ == "__main__":
    if sys.argv[1] == "serve":
        load_serve()({name: partial(command, name) for name in ("load", "write")}, warm)
    else:
        sys.stdout.write(json.dumps(command(*sys.argv[1:])) + "\n")
