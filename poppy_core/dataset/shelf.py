"""The datasets a folder holds (LeRobot's home: ``HOME/user/name``) and what the page's viewer
reads of one episode: its frames as JSON-ready lists, and each camera's video file and span.

Nothing here is written; every path given out is checked to lie inside its dataset's folder.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from poppy_core.dataset import layout
from poppy_core.dataset.reader import read_summary
from poppy_core.dataset.rows import episode_rows, find_episode
from poppy_core.errors import ArgumentError, PoppyError, UnknownNameError

DECIMALS = 3
"""Angles are sent in degrees to a thousandth: far finer than a servo reads."""


@dataclass(frozen=True)
class VideoSpan:
    """Where an episode lies in one camera's (concatenated) mp4 file, in seconds."""

    camera: str
    path: Path
    from_s: float
    to_s: float


def find_datasets(home: Path | None, extra: dict[str, Path]) -> dict[str, Path]:
    """repo_id -> folder of every dataset: ``extra`` (given by name), then each
    ``home/user/name`` holding a meta/info.json; sorted by name."""
    found: dict[str, Path] = {}
    if home is not None and home.is_dir():
        for info in home.glob(f"*/*/{layout.INFO_PATH}"):
            folder = info.parents[1]
            repo_id = f"{folder.parent.name}/{folder.name}"
            if layout.REPO_ID.fullmatch(repo_id):
                found[repo_id] = folder
    found.update(extra)
    return dict(sorted(found.items()))


def describe(repo_id: str, root: Path) -> dict[str, Any]:
    """A dataset as the page lists it; one that cannot be read says why in ``error``."""
    try:
        summary = read_summary(root)
    except PoppyError as exc:
        return {"repo_id": repo_id, "root": str(root), "error": str(exc), "episodes": []}
    except (KeyError, TypeError, ValueError) as exc:  # a table without LeRobot's columns
        error = f"{root} is no LeRobot v3.0 dataset ({type(exc).__name__}: {exc})"
        return {"repo_id": repo_id, "root": str(root), "error": error, "episodes": []}
    return {
        "repo_id": repo_id,
        "root": str(root),
        "robot_type": summary.robot_type,
        "fps": summary.fps,
        "cameras": list(summary.cameras),
        "joints": list(summary.joints),
        "frames": summary.frames,
        "episodes": [
            {
                "index": episode.index,
                "frames": episode.frames,
                "duration_s": round(episode.duration_s, 3),
                "tasks": list(episode.tasks),
            }
            for episode in summary.episodes
        ],
    }


def lookup(datasets: dict[str, Path], repo_id: str) -> Path:
    """The folder of ``repo_id``: a malformed name is an ArgumentError, an unknown one an
    UnknownNameError (the names there are listed by the datasets route)."""
    layout.check_repo_id(repo_id)
    if repo_id not in datasets:
        there = ", ".join(datasets) or "none"
        raise UnknownNameError(
            f"no dataset {repo_id!r} here (datasets: {there})",
            name=repo_id,
            known=list(datasets),
            kind="dataset",
        )
    return datasets[repo_id]


def episode_row(root: Path, episode: int) -> dict[str, Any]:
    """The episodes table's row of ``episode`` (UnknownNameError: no such episode)."""
    try:
        return find_episode(episode_rows(root), episode)
    except ArgumentError as exc:
        raise UnknownNameError(str(exc), name=str(episode), kind="episode") from None


def video_spans(root: Path, episode: int) -> list[VideoSpan]:
    """Each camera's file and the episode's span in it (meta/episodes' from/to timestamps);
    a file outside ``root`` (a link out of it) is refused."""
    from poppy_core.dataset import tables

    info = tables.read_json(root / layout.INFO_PATH)
    row = episode_row(root, episode)
    spans = []
    inside = root.resolve()
    for key, feature in (info.get("features") or {}).items():
        if not (isinstance(feature, dict) and feature.get("dtype") == "video"):
            continue
        try:
            path = root / layout.VIDEO_PATH.format(
                video_key=key,
                chunk_index=int(row[f"videos/{key}/chunk_index"]),
                file_index=int(row[f"videos/{key}/file_index"]),
            )
            from_s = float(row.get(f"videos/{key}/from_timestamp") or 0.0)
            to_s = float(row[f"videos/{key}/to_timestamp"])
        except (KeyError, TypeError, ValueError):
            raise ArgumentError(
                f"episode {episode} does not say where it lies in {key}'s video", field="episode"
            ) from None
        if not path.resolve().is_relative_to(inside):
            raise ArgumentError(f"{key}'s video lies outside the dataset's folder", field="video")
        spans.append(VideoSpan(key.removeprefix(layout.IMAGES), path, from_s, to_s))
    return spans


def video_file(root: Path, episode: int, camera: str) -> Path:
    """The mp4 file holding ``camera``'s frames of ``episode`` (UnknownNameError: no such
    camera)."""
    spans = {span.camera: span for span in video_spans(root, episode)}
    if camera not in spans:
        raise UnknownNameError(
            f"episode {episode} has no camera {camera!r} (cameras: {', '.join(spans) or 'none'})",
            name=camera,
            known=list(spans),
            kind="camera",
        )
    return spans[camera].path


def _rounded(rows: Any) -> list[list[float | None]]:
    return [
        [round(float(v), DECIMALS) if math.isfinite(float(v)) else None for v in row]
        for row in rows
    ]


def episode_frames(root: Path, episode: int) -> dict[str, Any]:
    """An episode for the page's player: timestamps, state and action per frame (degrees, one
    list per frame in ``motors`` order), the task, and each camera's span in its video."""
    from poppy_core.dataset.episode import read_episode

    episode_row(root, episode)
    chosen = read_episode(root, episode)
    return {
        "episode": chosen.index,
        "fps": chosen.fps,
        "robot_type": chosen.robot_type,
        "motors": list(chosen.motors),
        "tasks": list(chosen.tasks),
        "frames": len(chosen),
        "timestamps": [round(float(t), 6) for t in chosen.timestamps],
        "state": _rounded(chosen.states),
        "action": _rounded(chosen.actions),
        "videos": [
            {"camera": span.camera, "from_s": span.from_s, "to_s": span.to_s}
            for span in video_spans(root, episode)
        ],
    }
