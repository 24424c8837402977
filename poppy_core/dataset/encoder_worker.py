"""The video encoder's process: ``python -m poppy_core.dataset.encoder_worker RING SLOTS H W``.

Frames come through RING (a file of SLOTS frames of H x W x 3 bytes, mapped by both sides);
commands and replies are JSON lines on stdin and stdout (``encoder`` is the other side). A
frame index past the next one means the recorder dropped frames (no free slot): the last frame
is encoded again in their place, so frame k stays at k/fps and the video has a frame a row.
"""

from __future__ import annotations

import json
import mmap
import os
import sys
from pathlib import Path
from typing import Any, TextIO

import numpy as np
from numpy.typing import NDArray

from poppy_core.dataset.feature_stats import ImageStats
from poppy_core.dataset.video import ENCODING_ERRORS, Mp4File


def _reply(out: TextIO, *message: Any) -> None:
    out.write(json.dumps(message) + "\n")
    out.flush()


class _Episode:
    """One video being written: the file, its statistics, the last frame (for dropped ones)."""

    def __init__(self, path: Path, fps: int, width: int, height: int, codec: str) -> None:
        self.path = path
        self.stats = ImageStats()
        self.last: NDArray[np.uint8] | None = None
        self.filled = 0
        self.error: str | None = None
        try:
            self.file: Mp4File | None = Mp4File(path, fps, width, height, codec)
        except ENCODING_ERRORS as exc:
            self.file, self.error = None, str(exc)

    def add(self, frame: NDArray[np.uint8], index: int) -> None:
        if self.file is None or self.error is not None:
            return
        try:
            while self.file.frames < index:  # frames dropped before this one
                self._encode(self.last if self.last is not None else frame)
                self.filled += 1
            self._encode(frame)
        except ENCODING_ERRORS as exc:
            self.error = str(exc)
        self.last = np.array(frame)

    def _encode(self, frame: NDArray[np.uint8]) -> None:
        assert self.file is not None
        self.file.encode(frame)
        self.stats.add(frame)

    def finish(self, total: int) -> dict[str, Any]:
        if self.file is not None and self.error is None:
            try:
                if self.last is not None:
                    while self.file.frames < total:  # the last frames were dropped
                        self._encode(self.last)
                        self.filled += 1
                self.file.finish()
            except ENCODING_ERRORS as exc:
                self.error = str(exc)
        elif self.file is not None:
            self.file.close()
        return {
            "frames": self.file.frames if self.file is not None else 0,
            "filled": self.filled,
            "histogram": self.stats.histogram.tolist(),
            "stats_frames": self.stats.frames,
            "pixels": self.stats.pixels,
            "error": self.error,
        }

    def abandon(self) -> None:
        if self.file is not None:
            self.file.close()
        self.path.unlink(missing_ok=True)


def serve(ring_path: str, slots: int, height: int, width: int) -> None:
    """Answer the commands on stdin until ``quit`` or its end."""
    with open(ring_path, "r+b") as handle:
        mapped = mmap.mmap(handle.fileno(), slots * height * width * 3)
    ring = np.ndarray((slots, height, width, 3), dtype=np.uint8, buffer=mapped)
    out = sys.stdout
    _reply(out, "ready")
    episode: _Episode | None = None
    for line in sys.stdin:
        command = json.loads(line)
        kind = command[0]
        if kind == "frame":
            slot, index = int(command[1]), int(command[2])
            if episode is not None:
                episode.add(ring[slot], index)
            _reply(out, "free", slot)
        elif kind == "open":
            path, fps, codec = Path(command[1]), int(command[2]), str(command[3])
            episode = _Episode(path, fps, width, height, codec)
        elif kind == "finish" and episode is not None:
            _reply(out, "done", episode.finish(int(command[1])))
            episode = None
        elif kind == "abandon":
            if episode is not None:
                episode.abandon()
            episode = None
            _reply(out, "abandoned")
        elif kind == "quit":
            break
    if episode is not None:
        episode.abandon()


if __name__ == "__main__":
    os.environ.setdefault("SVT_LOG", "1")
    ring_file, count, rows, columns = sys.argv[1:5]
    serve(ring_file, int(count), int(rows), int(columns))
