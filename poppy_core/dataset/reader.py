"""What a LeRobotDataset v3.0 folder holds: episodes, frames, tasks, cameras (no frames read)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from poppy_core.dataset import layout, tables


@dataclass(frozen=True)
class EpisodeInfo:
    """One episode of a dataset."""

    index: int
    frames: int
    duration_s: float
    tasks: tuple[str, ...]


@dataclass(frozen=True)
class DatasetSummary:
    """A dataset at a glance (``poppy dataset info``)."""

    root: Path
    codebase_version: str
    robot_type: str | None
    fps: int
    frames: int
    tasks: tuple[str, ...]
    cameras: tuple[str, ...]
    joints: tuple[str, ...]
    episodes: tuple[EpisodeInfo, ...]

    @property
    def duration_s(self) -> float:
        """Recorded time over every episode."""
        return sum(episode.duration_s for episode in self.episodes)

    def as_json(self) -> dict[str, Any]:
        """The documented ``--json`` shape of ``poppy dataset info``."""
        return {
            "root": str(self.root),
            "codebase_version": self.codebase_version,
            "robot_type": self.robot_type,
            "fps": self.fps,
            "episodes": len(self.episodes),
            "frames": self.frames,
            "duration_s": round(self.duration_s, 3),
            "tasks": list(self.tasks),
            "cameras": list(self.cameras),
            "joints": list(self.joints),
        }


def read_summary(root: Path) -> DatasetSummary:
    """Read info.json, tasks and the episodes table of the dataset in ``root``."""
    root = Path(root).expanduser()
    info = tables.read_json(root / layout.INFO_PATH)
    fps = int(info.get("fps") or 0)
    features: dict[str, Any] = info.get("features") or {}
    tasks_path = root / layout.TASKS_PATH
    tasks = tables.read_tasks(tasks_path) if tasks_path.exists() else []
    rows: list[dict[str, Any]] = []
    for path in sorted((root / layout.EPISODES_DIR).glob("*/*.parquet")):
        rows.extend(tables.read_episodes(path))
    episodes = tuple(
        EpisodeInfo(
            index=int(row["episode_index"]),
            frames=int(row["length"]),
            duration_s=int(row["length"]) / fps if fps else 0.0,
            tasks=tuple(row.get("tasks") or ()),
        )
        for row in sorted(rows, key=lambda row: int(row["episode_index"]))
    )
    state = features.get(layout.STATE) or {}
    return DatasetSummary(
        root=root,
        codebase_version=str(info.get("codebase_version")),
        robot_type=info.get("robot_type"),
        fps=fps,
        frames=sum(episode.frames for episode in episodes),
        tasks=tuple(tasks),
        cameras=tuple(
            key.removeprefix(layout.IMAGES)
            for key, ft in features.items()
            if isinstance(ft, dict) and ft.get("dtype") == "video"
        ),
        joints=tuple(state.get("names") or ()),
        episodes=episodes,
    )
