"""The v3.0 layout: paths, features and info.json, and the rules of what a dataset may hold.

Facts from LeRobot 0.4.4 (``lerobot/datasets/utils.py``): the path templates, the default
features every frame carries, ``create_empty_dataset_info``'s keys and the chunk size (1000 files
per chunk). Poppy's own addition is a ``unit`` on the joint features (degrees, as its API).
"""

from __future__ import annotations

import math
import os
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from poppy_core.errors import ArgumentError

CODEBASE_VERSION = "v3.0"
CHUNK_SIZE = 1000
DATA_FILES_SIZE_IN_MB = 100
VIDEO_FILES_SIZE_IN_MB = 200
INFO_PATH = "meta/info.json"
STATS_PATH = "meta/stats.json"
TASKS_PATH = "meta/tasks.parquet"
EPISODES_DIR = "meta/episodes"
CHUNK_FILE = "chunk-{chunk_index:03d}/file-{file_index:03d}"
EPISODES_PATH = EPISODES_DIR + "/" + CHUNK_FILE + ".parquet"
DATA_PATH = "data/" + CHUNK_FILE + ".parquet"
VIDEO_PATH = "videos/{video_key}/" + CHUNK_FILE + ".mp4"
STATE = "observation.state"
ACTION = "action"
IMAGES = "observation.images."
UNIT = "degree"
DEFAULT_FEATURES: dict[str, dict[str, Any]] = {
    "timestamp": {"dtype": "float32", "shape": [1], "names": None},
    "frame_index": {"dtype": "int64", "shape": [1], "names": None},
    "episode_index": {"dtype": "int64", "shape": [1], "names": None},
    "index": {"dtype": "int64", "shape": [1], "names": None},
    "task_index": {"dtype": "int64", "shape": [1], "names": None},
}
MAX_FPS = 240
MAX_TASK = 1000
NAME = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.-]{0,63}")
REPO_ID = re.compile(r"[A-Za-z0-9_.-]{1,96}/[A-Za-z0-9_.-]{1,96}")


@dataclass(frozen=True)
class DatasetSpec:
    """What each frame holds: the motors (state and action, in degrees) and the cameras."""

    fps: int
    motors: tuple[str, ...]
    cameras: dict[str, tuple[int, int]] = field(default_factory=dict)
    """Camera name -> (height, width) of its frames."""
    robot_type: str | None = None

    def __post_init__(self) -> None:
        check_fps(self.fps)
        if not self.motors:
            raise ArgumentError("a dataset needs at least one motor", field="motors")
        for name in (*self.motors, *self.cameras):
            if not NAME.fullmatch(name):
                raise ArgumentError(
                    f"{name!r} cannot name a feature: use letters, digits, '_', '.', '-'",
                    field="name",
                    value=name,
                )
        if len(set(self.motors)) != len(self.motors):
            raise ArgumentError("a motor is named twice", field="motors")
        for name, (height, width) in self.cameras.items():
            if not (16 <= height <= 4320 and 16 <= width <= 7680) or height % 2 or width % 2:
                raise ArgumentError(
                    f"camera {name}: {width}x{height} is not an even size from 16x16 to 7680x4320",
                    field="cameras",
                    value=(height, width),
                )

    def video_keys(self) -> list[str]:
        """The features that are videos, one per camera."""
        return [IMAGES + name for name in self.cameras]

    def features(self, video_info: dict[str, dict[str, Any]] | None = None) -> dict[str, Any]:
        """info.json's ``features``: LeRobot's order (the recorded ones, then the defaults)."""
        names = [f"{motor}.pos" for motor in self.motors]
        joints = {"dtype": "float32", "shape": [len(names)], "names": names, "unit": UNIT}
        features: dict[str, Any] = {ACTION: dict(joints), STATE: dict(joints)}
        for name, (height, width) in self.cameras.items():
            key = IMAGES + name
            features[key] = {
                "dtype": "video",
                "shape": [height, width, 3],
                "names": ["height", "width", "channels"],
            }
            if video_info and key in video_info:
                features[key]["info"] = video_info[key]
        features.update({key: dict(value) for key, value in DEFAULT_FEATURES.items()})
        return features

    @classmethod
    def from_info(cls, info: dict[str, Any]) -> DatasetSpec:
        """The spec of a dataset poppy wrote (its info.json)."""
        features = info.get("features", {})
        try:
            names = features[STATE]["names"]
            motors = tuple(str(name).removesuffix(".pos") for name in names)
            cameras = {
                key.removeprefix(IMAGES): (int(ft["shape"][0]), int(ft["shape"][1]))
                for key, ft in features.items()
                if ft.get("dtype") == "video" and key.startswith(IMAGES)
            }
            return cls(int(info["fps"]), motors, cameras, info.get("robot_type"))
        except (KeyError, TypeError, ValueError, IndexError) as exc:
            raise ArgumentError(
                f"info.json does not describe a poppy recording ({exc})", field="root"
            ) from None


def empty_info(spec: DatasetSpec) -> dict[str, Any]:
    """info.json of a dataset with no episode yet (LeRobot's ``create_empty_dataset_info``)."""
    return {
        "codebase_version": CODEBASE_VERSION,
        "robot_type": spec.robot_type,
        "total_episodes": 0,
        "total_frames": 0,
        "total_tasks": 0,
        "chunks_size": CHUNK_SIZE,
        "data_files_size_in_mb": DATA_FILES_SIZE_IN_MB,
        "video_files_size_in_mb": VIDEO_FILES_SIZE_IN_MB,
        "fps": spec.fps,
        "splits": {},
        "data_path": DATA_PATH,
        "video_path": VIDEO_PATH if spec.cameras else None,
        "features": spec.features(),
    }


def lerobot_home() -> Path:
    """LeRobot's datasets folder: $HF_LEROBOT_HOME, else $HF_HOME/lerobot, else
    ~/.cache/huggingface/lerobot (LeRobot 0.4.4's ``HF_LEROBOT_HOME``)."""
    home = os.environ.get("HF_LEROBOT_HOME")
    if home:
        return Path(home).expanduser()
    hf_home = os.environ.get("HF_HOME") or str(Path.home() / ".cache" / "huggingface")
    return Path(hf_home).expanduser() / "lerobot"


def chunk_and_file(position: int) -> tuple[int, int]:
    """The (chunk, file) indices of the ``position``-th file of a kind (1000 files a chunk)."""
    return divmod(position, CHUNK_SIZE)


def check_fps(fps: object) -> int:
    """A recording rate: a whole number of frames per second, 1 to 240."""
    if isinstance(fps, bool) or not isinstance(fps, int) or not 1 <= fps <= MAX_FPS:
        raise ArgumentError(
            f"fps must be a whole number from 1 to {MAX_FPS}, not {fps!r}", field="fps", value=fps
        )
    return fps


def check_task(task: object) -> str:
    """A task: one line of printable text (what the policy is told), 1 to 1000 characters."""
    if not isinstance(task, str) or not task.strip():
        raise ArgumentError("the task must be a non-empty text", field="task", value=task)
    if len(task) > MAX_TASK:
        raise ArgumentError(f"the task is longer than {MAX_TASK} characters", field="task")
    if any(not ch.isprintable() for ch in task):
        raise ArgumentError(
            "the task holds a control character (a newline, tab or escape): write it on one line",
            field="task",
            value=task,
        )
    return task


def check_repo_id(repo_id: object) -> str:
    """A dataset's name as LeRobot's hub knows it: ``user/name``."""
    if not isinstance(repo_id, str) or not REPO_ID.fullmatch(repo_id) or ".." in repo_id:
        raise ArgumentError(
            f"{repo_id!r} is not a dataset name: write it as user/name "
            "(letters, digits, '_', '.', '-')",
            field="repo_id",
            value=repo_id,
        )
    return repo_id


def check_values(values: object, count: int, what: str) -> list[float]:
    """``count`` finite angles in degrees (|x| < 100000): NaN, inf and 1e9 are refused."""
    try:
        numbers = [float(value) for value in values]  # type: ignore[attr-defined]
    except (TypeError, ValueError):
        raise ArgumentError(f"{what} must be {count} numbers", field=what) from None
    if len(numbers) != count:
        raise ArgumentError(f"{what} has {len(numbers)} values, not {count}", field=what)
    for number in numbers:
        if not math.isfinite(number) or abs(number) >= 1e5:
            raise ArgumentError(
                f"{what} holds {number!r}: angles must be finite degrees", field=what, value=number
            )
    return numbers
