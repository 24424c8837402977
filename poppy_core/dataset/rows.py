"""One episode of a dataset poppy wrote: its rows found, its actions read (for a replay)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from poppy_core.dataset import feature_stats as stats
from poppy_core.dataset import layout, tables
from poppy_core.errors import ArgumentError


@dataclass(frozen=True)
class EpisodeActions:
    """An episode's ``action`` columns: one row per frame, one column per motor (degrees)."""

    episode: int
    fps: int
    motors: tuple[str, ...]
    positions: NDArray[np.float64]


def episode_rows(root: Path) -> list[dict[str, Any]]:
    """The episodes table's rows (every file of meta/episodes), in episode order."""
    rows: list[dict[str, Any]] = []
    for path in sorted((Path(root) / layout.EPISODES_DIR).glob("*/*.parquet")):
        rows.extend(tables.read_episodes(path))
    return sorted(rows, key=lambda row: int(row["episode_index"]))


def find_episode(rows: list[dict[str, Any]], episode: int) -> dict[str, Any]:
    """The row of ``episode``; an ArgumentError naming the episodes there are otherwise."""
    for row in rows:
        if int(row["episode_index"]) == episode:
            return row
    there = f"0 to {len(rows) - 1}" if rows else "none"
    raise ArgumentError(
        f"no episode {episode} in this dataset (episodes: {there})", field="episode", value=episode
    )


def data_path(root: Path, row: dict[str, Any]) -> Path:
    """The data file that holds an episode's frames."""
    return Path(root) / layout.DATA_PATH.format(
        chunk_index=int(row["data/chunk_index"]), file_index=int(row["data/file_index"])
    )


def read_actions(root: Path, episode: int) -> EpisodeActions:
    """The ``action`` of every frame of ``episode``, in frame order."""
    root = Path(root).expanduser()
    info = tables.read_json(root / layout.INFO_PATH)
    action = (info.get("features") or {}).get(layout.ACTION) or {}
    names = action.get("names")
    if not isinstance(names, list) or not names:
        raise ArgumentError(f"{root} holds no action joints in its info.json", field="root")
    motors = tuple(str(name).removesuffix(".pos") for name in names)
    row = find_episode(episode_rows(root), episode)
    table = tables.read_table(data_path(root, row)).to_pydict()
    frames = sorted(
        (int(frame), values)
        for index, frame, values in zip(
            table["episode_index"], table["frame_index"], table[layout.ACTION], strict=True
        )
        if int(index) == episode
    )
    if not frames:
        raise ArgumentError(f"episode {episode} has no frame in its data file", field="episode")
    positions = np.asarray([values for _, values in frames], dtype=np.float64)
    positions = positions.reshape(len(frames), len(motors))  # one joint: a scalar column
    return EpisodeActions(episode, layout.check_fps(int(info.get("fps") or 0)), motors, positions)


def stats_of_row(row: dict[str, Any]) -> dict[str, stats.Stats]:
    """An episode's stats back from its ``stats/<feature>/<name>`` columns."""
    found: dict[str, stats.Stats] = {}
    for column, value in row.items():
        if column.startswith("stats/") and value is not None:
            key, _, name = column.removeprefix("stats/").rpartition("/")
            found.setdefault(key, {})[name] = np.asarray(value)
    return found
