"""Datasets for the viewer's tests: written by poppy's writer (synthetic camera frames), then
their videos packed as LeRobot packs them (every episode in one mp4, each naming its span)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from poppy_core.dataset import layout, tables
from poppy_core.dataset.layout import DatasetSpec
from poppy_core.dataset.rows import episode_rows
from poppy_core.dataset.video import Mp4File, pick_codec
from poppy_core.dataset.writer import DatasetWriter

MOTORS = tuple(f"m{i}" for i in range(1, 7))
FPS = 10
SIZE = (120, 160)  # height, width
EPISODES = ((3, "stay"), (30, "wave"))
"""Frames and task of each episode."""


def state(k: int) -> list[float]:
    """Frame k's state (degrees, inside the Ergo Jr's limits)."""
    return [2.0 * k, -k, 0.5 * k, 10.0, -20.0, -1.5 * k]


def action(k: int) -> list[float]:
    """Frame k's action: the state with 5 degrees more on every joint."""
    return [value + 5.0 for value in state(k)]


def image(k: int) -> np.ndarray:
    """Frame k's picture: its red level says k."""
    picture = np.zeros((*SIZE, 3), np.uint8)
    picture[..., 0] = min(255, 8 * k)
    picture[..., 1] = 100
    return picture


def write_dataset(root: Path, robot_type: str | None = "ergo-jr", codec: str | None = None) -> None:
    """EPISODES recorded with one camera, ``top``, then packed (``pack_videos``) with
    ``codec`` (default: the one poppy's writer picks)."""
    spec = DatasetSpec(FPS, MOTORS, {"top": SIZE}, robot_type)
    with DatasetWriter.create(root, spec, codec) as writer:
        for frames, task in EPISODES:
            writer.begin_episode(task)
            for k in range(frames):
                writer.add_frame(state(k), action(k), {"top": image(k)})
            writer.save_episode()
    pack_videos(root, codec or pick_codec())


def pack_videos(root: Path, codec: str) -> None:
    """Every episode's frames of each camera in file-000 one after the other, each episode's
    from/to timestamps naming its span there (LeRobot v3.0's concatenated files)."""
    import av

    info = tables.read_json(root / layout.INFO_PATH)
    keys = [k for k, ft in info["features"].items() if ft.get("dtype") == "video"]
    rows = episode_rows(root)
    fps = int(info["fps"])
    for key in keys:
        pictures: list[Any] = []
        spans = []
        for row in rows:
            path = root / layout.VIDEO_PATH.format(
                video_key=key,
                chunk_index=int(row[f"videos/{key}/chunk_index"]),
                file_index=int(row[f"videos/{key}/file_index"]),
            )
            with av.open(str(path)) as container:
                own = [f.to_ndarray(format="rgb24") for f in container.decode(video=0)]
            spans.append((len(pictures), len(own)))
            pictures.extend(own)
            path.unlink()
        packed = root / layout.VIDEO_PATH.format(video_key=key, chunk_index=0, file_index=0)
        height, width = pictures[0].shape[:2]
        out = Mp4File(packed.with_suffix(".tmp.mp4"), fps, width, height, codec)
        for picture in pictures:
            out.encode(picture)
        out.finish()
        packed.with_suffix(".tmp.mp4").replace(packed)
        for row, (start, length) in zip(rows, spans, strict=True):
            row[f"videos/{key}/chunk_index"] = 0
            row[f"videos/{key}/file_index"] = 0
            row[f"videos/{key}/from_timestamp"] = start / fps
            row[f"videos/{key}/to_timestamp"] = (start + length) / fps
    tables.write_table(
        root / layout.EPISODES_PATH.format(chunk_index=0, file_index=0),
        tables.episodes_table(rows),
    )
