"""Record episodes into a LeRobotDataset v3.0 folder, one episode at a time.

Each saved episode gets its own data file and, per camera, its own video file (v3.0 allows
several episodes per file; one each keeps every save a few atomic renames). The order of a
save: frames, videos, tasks, the episodes table, stats.json, info.json last. A recording killed
mid-episode leaves only hidden temporary files beside the finished episodes: the dataset loads
as it was, and ``resume`` removes the leftovers and files no episode row names.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from poppy_core.dataset import feature_stats as stats
from poppy_core.dataset import layout, tables
from poppy_core.dataset.encoder import VideoEncoder
from poppy_core.dataset.layout import DatasetSpec
from poppy_core.dataset.rows import stats_of_row
from poppy_core.dataset.video import pick_codec, video_info
from poppy_core.errors import ArgumentError, FileError

LEFTOVER = re.compile(r"\..+\.(tmp|recording)$")


@dataclass(frozen=True)
class EpisodeSaved:
    """What one saved episode holds."""

    index: int
    frames: int
    duration_s: float
    task: str
    video_dropped: int = 0
    """Camera frames the encoders could not take in time (the last one stands in for each)."""


class DatasetWriter:
    """Episodes into ``root``: ``begin_episode``, ``add_frame``..., ``save_episode``."""

    def __init__(self, root: Path, spec: DatasetSpec, info: dict[str, Any], codec: str) -> None:
        self.root = root
        self.spec = spec
        self.info = info
        self.codec = codec
        self.episodes: list[dict[str, Any]] = []
        self.tasks: list[str] = []
        self._episode_stats: list[dict[str, stats.Stats]] = []
        self._task: str | None = None
        self._states: list[list[float]] = []
        self._actions: list[list[float]] = []
        self._encoders: dict[str, VideoEncoder] = {}
        self._videos: dict[str, VideoEncoder] = {}

    # -- opening ---------------------------------------------------------------------------

    @classmethod
    def create(cls, root: Path, spec: DatasetSpec, codec: str | None = None) -> DatasetWriter:
        """A new dataset in ``root``, which must not exist yet (nothing is ever overwritten)."""
        root = Path(root).expanduser()
        if root.exists() or root.is_symlink():
            raise ArgumentError(
                f"{root} already exists: pass --resume to add episodes, or choose another --root",
                field="root",
                value=str(root),
            )
        try:
            root.mkdir(parents=True)
        except OSError as exc:
            raise FileError(f"cannot create {root}: {exc.strerror}", path=str(root)) from None
        writer = cls(root, spec, layout.empty_info(spec), codec or pick_codec())
        tables.write_json(root / layout.INFO_PATH, writer.info)
        return writer

    @classmethod
    def resume(cls, root: Path, spec: DatasetSpec, codec: str | None = None) -> DatasetWriter:
        """Add episodes to the dataset in ``root``, recorded with the same ``spec``."""
        root = Path(root).expanduser()
        info = tables.read_json(root / layout.INFO_PATH)
        if info.get("codebase_version") != layout.CODEBASE_VERSION:
            raise ArgumentError(
                f"{root} is a LeRobot dataset {info.get('codebase_version')}, not "
                f"{layout.CODEBASE_VERSION}: convert it with LeRobot first",
                field="root",
            )
        mine = spec.features()
        theirs = {
            key: {k: v for k, v in ft.items() if k != "info"}
            for key, ft in info.get("features", {}).items()
        }
        if int(info.get("fps", 0)) != spec.fps or theirs != mine:
            raise ArgumentError(
                f"{root} holds other features or another fps ({info.get('fps')}): "
                "resume with the same robot, cameras and --fps, or choose another --root",
                field="root",
            )
        writer = cls(root, spec, info, codec or pick_codec())
        writer._load()
        return writer

    def _load(self) -> None:
        episodes_path = self.root / layout.EPISODES_PATH.format(chunk_index=0, file_index=0)
        if episodes_path.exists():
            self.episodes = tables.read_episodes(episodes_path)
        tasks_path = self.root / layout.TASKS_PATH
        if tasks_path.exists():
            self.tasks = tables.read_tasks(tasks_path)
        self._episode_stats = [stats_of_row(row) for row in self.episodes]
        self._remove_leftovers()
        self._write_summary()

    def _remove_leftovers(self) -> None:
        """Temporary files of a killed recording, and files that no episode row names."""
        named = {self.root / layout.EPISODES_PATH.format(chunk_index=0, file_index=0)}
        for row in self.episodes:
            named.add(
                self.root
                / layout.DATA_PATH.format(
                    chunk_index=row["data/chunk_index"], file_index=row["data/file_index"]
                )
            )
            for key in self.spec.video_keys():
                named.add(
                    self.root
                    / layout.VIDEO_PATH.format(
                        video_key=key,
                        chunk_index=row[f"videos/{key}/chunk_index"],
                        file_index=row[f"videos/{key}/file_index"],
                    )
                )
        for folder in ("data", "videos", layout.EPISODES_DIR):
            for path in sorted((self.root / folder).rglob("*")):
                stray = path.suffix in (".parquet", ".mp4") and path not in named
                if path.is_file() and (stray or LEFTOVER.fullmatch(path.name)):
                    path.unlink(missing_ok=True)  # an encoder's process may remove its own

    # -- recording -------------------------------------------------------------------------

    @property
    def recording(self) -> bool:
        """An episode is open."""
        return self._task is not None

    @property
    def frames(self) -> int:
        """Frames in the open episode."""
        return len(self._states)

    def begin_episode(self, task: str) -> None:
        """Open the next episode, described by ``task``."""
        if self.recording:
            raise ArgumentError("an episode is already open: save or discard it first")
        self._task = layout.check_task(task)
        self._states, self._actions = [], []
        position = len(self.episodes)
        for name, (height, width) in self.spec.cameras.items():
            path = self._video_path(layout.IMAGES + name, position)
            path = path.with_name(f".{path.name}.{os.getpid()}.recording")
            path.parent.mkdir(parents=True, exist_ok=True)
            if name not in self._encoders:
                slots = max(4, self.spec.fps)  # a second of frames
                self._encoders[name] = VideoEncoder(name, height, width, slots)
            self._encoders[name].open(path, self.spec.fps, self.codec)
            self._videos[name] = self._encoders[name]

    def add_frame(
        self,
        state: Any,
        action: Any,
        images: dict[str, NDArray[np.uint8]] | None = None,
        *,
        live: bool = False,
    ) -> None:
        """One frame: the state and the action (degrees, in the spec's motor order), and an RGB
        image (height x width x 3, uint8) from every camera. ``live``: never wait for an
        encoder a second behind, drop the image instead (the last one stands in for it)."""
        if not self.recording:
            raise ArgumentError("no episode is open: call begin_episode first")
        count = len(self.spec.motors)
        state_row = layout.check_values(state, count, "state")
        action_row = layout.check_values(action, count, "action")
        images = images or {}
        if set(images) != set(self.spec.cameras):
            raise ArgumentError(
                f"a frame needs an image from each camera "
                f"({', '.join(self.spec.cameras) or 'none'}), got {', '.join(images) or 'none'}",
                field="images",
            )
        for name, image in images.items():
            height, width = self.spec.cameras[name]
            if image.shape != (height, width, 3) or image.dtype != np.uint8:
                raise ArgumentError(
                    f"camera {name}: a frame of {image.shape} {image.dtype}, "
                    f"not ({height}, {width}, 3) uint8",
                    field="images",
                )
        for name, image in images.items():
            self._videos[name].add(image, drop=live)
        self._states.append(state_row)
        self._actions.append(action_row)

    def discard_episode(self) -> None:
        """Drop the open episode (its frames and videos); the dataset is as before."""
        for video in self._videos.values():
            video.abandon()
        self._videos.clear()
        self._task = None
        self._states, self._actions = [], []

    def save_episode(self) -> EpisodeSaved:
        """Write the open episode; it is in the dataset once this returns."""
        if self._task is None:
            raise ArgumentError("no episode is open")
        if not self._states:
            raise ArgumentError("the episode has no frame: discard it instead")
        task = self._task
        index = len(self.episodes)
        length = len(self._states)
        start = int(self.info["total_frames"])
        if task not in self.tasks:
            self.tasks.append(task)
        task_index = self.tasks.index(task)
        columns: dict[str, Any] = {
            layout.ACTION: np.asarray(self._actions, dtype=np.float32),
            layout.STATE: np.asarray(self._states, dtype=np.float32),
            "timestamp": (np.arange(length, dtype=np.float64) / self.spec.fps).astype(np.float32),
            "frame_index": np.arange(length, dtype=np.int64),
            "episode_index": np.full(length, index, dtype=np.int64),
            "index": np.arange(start, start + length, dtype=np.int64),
            "task_index": np.full(length, task_index, dtype=np.int64),
        }
        episode_stats = {key: stats.vector_stats(value) for key, value in columns.items()}
        chunk, file = layout.chunk_and_file(index)
        row: dict[str, Any] = {
            "episode_index": index,
            "tasks": [task],
            "length": length,
            "data/chunk_index": chunk,
            "data/file_index": file,
            "dataset_from_index": start,
            "dataset_to_index": start + length,
        }
        features = self.spec.features()
        data_path = self.root / layout.DATA_PATH.format(chunk_index=chunk, file_index=file)
        tables.write_table(data_path, tables.frames_table(columns, features))
        video_dropped = 0
        for name, video in self._videos.items():
            key = layout.IMAGES + name
            encoded = video.finish()
            if encoded.frames != length or video.path is None:
                raise FileError(f"camera {name}: {encoded.frames} frames encoded of {length}")
            video_dropped += encoded.filled
            final = self._video_path(key, index)
            os.replace(video.path, final)
            episode_stats[key] = encoded.stats.result()
            row[f"videos/{key}/chunk_index"] = chunk
            row[f"videos/{key}/file_index"] = file
            row[f"videos/{key}/from_timestamp"] = 0.0
            row[f"videos/{key}/to_timestamp"] = length / self.spec.fps
            if "info" not in self.info["features"][key]:
                self.info["features"][key]["info"] = video_info(final, self.spec.fps)
        self._videos.clear()
        for key, feature_stats in episode_stats.items():
            for name, value in feature_stats.items():
                row[f"stats/{key}/{name}"] = value.tolist()
        row["meta/episodes/chunk_index"] = 0
        row["meta/episodes/file_index"] = 0
        tables.write_table(self.root / layout.TASKS_PATH, tables.tasks_table(self.tasks))
        self.episodes.append(row)
        self._episode_stats.append(episode_stats)
        episodes_path = self.root / layout.EPISODES_PATH.format(chunk_index=0, file_index=0)
        tables.write_table(episodes_path, tables.episodes_table(self.episodes))
        self._write_summary()
        self._task = None
        self._states, self._actions = [], []
        return EpisodeSaved(index, length, length / self.spec.fps, task, video_dropped)

    def _write_summary(self) -> None:
        """stats.json, then info.json, from the episode rows."""
        total = sum(int(row["length"]) for row in self.episodes)
        self.info.update(
            total_episodes=len(self.episodes),
            total_frames=total,
            total_tasks=len(self.tasks),
            splits={"train": f"0:{len(self.episodes)}"} if self.episodes else {},
        )
        if self._episode_stats:
            merged = stats.aggregate_all(self._episode_stats)
            tables.write_json(self.root / layout.STATS_PATH, stats.to_json(merged))
        tables.write_json(self.root / layout.INFO_PATH, self.info)

    def _video_path(self, key: str, position: int) -> Path:
        chunk, file = layout.chunk_and_file(position)
        return self.root / layout.VIDEO_PATH.format(
            video_key=key, chunk_index=chunk, file_index=file
        )

    @property
    def video_dropped(self) -> int:
        """Camera frames of the open episode that the encoders could not take in time."""
        return sum(video.dropped for video in self._videos.values())

    def close(self) -> None:
        """Drop an episode still open (it was not saved); end the encoders' processes."""
        if self.recording:
            self.discard_episode()
        for encoder in self._encoders.values():
            encoder.close()
        self._encoders.clear()

    def __enter__(self) -> DatasetWriter:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def default_root(repo_id: str) -> Path:
    """Where LeRobot looks for ``repo_id`` without --root (``layout.lerobot_home()``)."""
    return layout.lerobot_home() / repo_id
