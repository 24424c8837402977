"""A recorded episode as a Rerun recording (``.rrd``, rerun-sdk: ``poppy dataset view --rerun``).

The entities are named as LeRobot's own Rerun view names them: ``observation.state/NAME`` and
``action/NAME`` (one scalar a motor, in degrees), ``observation.images.CAMERA`` (each frame as
a JPEG), ``task`` (a text document). Every row is on two timelines: ``frame`` (the frame's
number) and ``time`` (its timestamp, from the episode's start). The file is written beside the
target under a temporary name and put in place when whole.
"""

from __future__ import annotations

import contextlib
import os
import secrets
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from poppy_core.dataset import layout
from poppy_core.dataset.episode import Episode, video_frames
from poppy_core.dataset.video import JpegEncoder
from poppy_core.errors import FileError
from poppy_core.files import file_error, output_path, place_file

APPLICATION = "poppy"


@dataclass(frozen=True)
class RerunExport:
    """What was written: the file and the rows of each entity."""

    path: Path
    rows: dict[str, int]


def write_episode_rrd(
    episode: Episode, path: str | os.PathLike[str], *, name: str, replace: bool = False
) -> RerunExport:
    """Write ``episode`` into the Rerun file ``path`` (``name``: the recording's id, e.g. the
    dataset's repo id and the episode).

    Raises:
        FileError: the target cannot be written (a missing folder, a file there without
            ``replace``...); a file there before is left as it was.
    """
    import rerun as rr

    target = output_path(path, replace=replace)
    temp = target.parent / f".{target.name[:200]}.{secrets.token_hex(6)}.tmp"
    rows: dict[str, int] = {}
    try:
        recording = rr.RecordingStream(APPLICATION, recording_id=name)
        recording.set_log_time_enabled(False)  # the dataset's times only, not the export's
        recording.save(temp)
        try:
            frames = np.arange(len(episode), dtype=np.int64)
            times = np.asarray(episode.timestamps, dtype=np.float64)
            indexes = [
                rr.TimeColumn("frame", sequence=frames),
                rr.TimeColumn("time", duration=times),
            ]
            for key, values in ((layout.STATE, episode.states), (layout.ACTION, episode.actions)):
                for column, motor in enumerate(episode.motors):
                    entity = f"{key}/{motor}"
                    scalars = rr.Scalars.columns(scalars=values[:, column])
                    recording.send_columns(entity, indexes=indexes, columns=scalars)
                    rows[entity] = len(frames)
            recording.log("task", rr.TextDocument("\n".join(episode.tasks)), static=True)
            rows["task"] = 1
            for video in episode.videos:
                entity = layout.IMAGES + video.camera
                jpeg = JpegEncoder()
                rows[entity] = 0
                for k, image in video_frames(episode, video):
                    recording.set_time("frame", sequence=k)
                    recording.set_time("time", duration=float(times[k]))
                    picture = rr.EncodedImage(contents=jpeg.encode(image), media_type="image/jpeg")
                    recording.log(entity, picture)
                    rows[entity] += 1
            recording.flush()
        finally:
            recording.disconnect()
        place_file(temp, target, replace=replace)
    except OSError as exc:
        raise file_error(exc, target, "write") from None
    except RuntimeError as exc:  # the SDK's own errors (a full disk...)
        raise FileError(f"cannot write {target}: {exc}", path=str(target)) from None
    finally:
        with contextlib.suppress(OSError):
            os.unlink(temp)
    return RerunExport(target, rows)
