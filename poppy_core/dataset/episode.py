"""One whole episode of a dataset read back: timestamps, state, action, task and its videos'
frames (for the exports: ``poppy dataset view --mcap``/``--rerun``)."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from poppy_core.dataset import layout, tables
from poppy_core.dataset.rows import data_path, episode_rows, find_episode
from poppy_core.errors import ArgumentError


@dataclass(frozen=True)
class EpisodeVideo:
    """One camera's frames of an episode: the file and where the episode starts in it."""

    camera: str
    path: Path
    from_s: float


@dataclass(frozen=True)
class Episode:
    """An episode in frame order: ``timestamps`` (s from its start), ``states`` and
    ``actions`` (one row per frame, one column per motor, in degrees)."""

    root: Path
    index: int
    fps: int
    robot_type: str | None
    motors: tuple[str, ...]
    tasks: tuple[str, ...]
    timestamps: NDArray[np.float64]
    states: NDArray[np.float64]
    actions: NDArray[np.float64]
    videos: tuple[EpisodeVideo, ...] = field(default=())

    def __len__(self) -> int:
        return len(self.timestamps)


def read_episode(root: Path, episode: int) -> Episode:
    """Episode ``episode`` of the dataset in ``root``.

    Raises:
        ArgumentError: no such episode, no joints in info.json, or an episode without frames.
    """
    root = Path(root).expanduser()
    info = tables.read_json(root / layout.INFO_PATH)
    features: dict[str, Any] = info.get("features") or {}
    names = (features.get(layout.STATE) or {}).get("names")
    if not isinstance(names, list) or not names:
        raise ArgumentError(f"{root} holds no state joints in its info.json", field="root")
    motors = tuple(str(name).removesuffix(".pos") for name in names)
    fps = layout.check_fps(int(info.get("fps") or 0))
    row = find_episode(episode_rows(root), episode)
    table = tables.read_table(data_path(root, row)).to_pydict()
    picked = sorted(
        (int(frame), k)
        for k, (index, frame) in enumerate(
            zip(table["episode_index"], table["frame_index"], strict=True)
        )
        if int(index) == episode
    )
    if not picked:
        raise ArgumentError(f"episode {episode} has no frame in its data file", field="episode")
    order = [k for _, k in picked]

    def column(key: str) -> NDArray[np.float64]:
        values = np.asarray([table[key][k] for k in order], dtype=np.float64)
        return values.reshape(len(order), -1)

    videos = tuple(
        EpisodeVideo(
            key.removeprefix(layout.IMAGES),
            root
            / layout.VIDEO_PATH.format(
                video_key=key,
                chunk_index=int(row[f"videos/{key}/chunk_index"]),
                file_index=int(row[f"videos/{key}/file_index"]),
            ),
            float(row.get(f"videos/{key}/from_timestamp") or 0.0),
        )
        for key, feature in features.items()
        if isinstance(feature, dict) and feature.get("dtype") == "video"
    )
    return Episode(
        root=root,
        index=episode,
        fps=fps,
        robot_type=info.get("robot_type"),
        motors=motors,
        tasks=tuple(str(task) for task in row.get("tasks") or ()),
        timestamps=column("timestamp")[:, 0],
        states=column(layout.STATE),
        actions=column(layout.ACTION),
        videos=videos,
    )


def video_frames(episode: Episode, video: EpisodeVideo) -> Iterator[tuple[int, NDArray[np.uint8]]]:
    """(frame number, RGB image) of the episode's frames in ``video``: a decoded picture is
    frame k when it is stamped ``from_s + timestamps[k]`` (within half a frame)."""
    import av

    wanted = {
        round((video.from_s + float(t)) * episode.fps): k for k, t in enumerate(episode.timestamps)
    }
    with av.open(str(video.path), "r") as container:
        for picture in container.decode(video=0):
            if picture.time is None:
                continue
            k = wanted.get(round(float(picture.time) * episode.fps))
            if k is not None:
                yield k, np.asarray(picture.to_ndarray(format="rgb24"), dtype=np.uint8)
