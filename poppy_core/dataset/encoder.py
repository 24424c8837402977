"""A camera's video encoded in a process of its own, fed through shared memory, never blocking.

``VideoEncoder`` starts ``encoder_worker`` (``python -m``) once and keeps it for every episode.
Frames go into a ring of ``slots`` frames mapped by both processes (one second of frames by
default: memory bounded); a frame that finds no free slot (the encoder a second behind) is
dropped and counted, and the worker encodes the last frame again in its place, so the video
keeps a frame per row at k/fps. The image statistics are gathered in the worker too.
"""

from __future__ import annotations

import collections
import contextlib
import json
import mmap
import os
import queue
import subprocess
import sys
import tempfile
import threading
import weakref
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any

import numpy as np
from numpy.typing import NDArray

from poppy_core.dataset.feature_stats import ImageStats
from poppy_core.errors import FileError

START_TIMEOUT_S = 60.0
WAIT_S = 1.0


@dataclass
class EncodedVideo:
    """One finished video: its frames, those filled in for dropped ones, its statistics."""

    frames: int
    filled: int
    stats: ImageStats


def _read(
    stdout: IO[bytes] | None,
    free: collections.deque[int],
    freed: threading.Event,
    replies: queue.Queue[list[Any] | None],
) -> None:
    """The worker's replies: freed slots into ``free``, the others into ``replies``."""
    assert stdout is not None
    for line in stdout:
        message = json.loads(line)
        if message[0] == "free":
            free.append(int(message[1]))
            freed.set()
        else:
            replies.put(message)
    replies.put(None)
    freed.set()


def _close_stdin(proc: subprocess.Popen[bytes]) -> None:
    if proc.stdin is not None:
        with contextlib.suppress(OSError):
            proc.stdin.close()


class VideoEncoder:
    """Frames of ``height`` x ``width`` (RGB, uint8) to MP4 files, one ``open`` ... ``finish``
    (or ``abandon``) per episode."""

    def __init__(self, name: str, height: int, width: int, slots: int) -> None:
        self.name = name
        self.shape = (height, width, 3)
        self.dropped = 0
        self.path: Path | None = None
        self._sent = 0
        self._free: collections.deque[int] = collections.deque(range(slots))
        self._replies: queue.Queue[list[Any] | None] = queue.Queue()
        self._freed = threading.Event()
        size = slots * height * width * 3
        folder = "/dev/shm" if os.path.isdir("/dev/shm") else None
        fd, ring_path = tempfile.mkstemp(prefix="poppy-video-", dir=folder)
        try:
            os.ftruncate(fd, size)
            self._mapped = mmap.mmap(fd, size)
            os.close(fd)
            self._ring = np.ndarray((slots, *self.shape), dtype=np.uint8, buffer=self._mapped)
            env = dict(os.environ)
            env.setdefault("SVT_LOG", "1")  # SVT-AV1's banner, else printed on every episode
            worker = [sys.executable, "-m", "poppy_core.dataset.encoder_worker", ring_path]
            self._proc = subprocess.Popen(
                [*worker, str(slots), str(height), str(width)],
                stdin=subprocess.PIPE,
                stdout=subprocess.PIPE,
                env=env,
            )
            self._reader = threading.Thread(
                target=_read,
                args=(self._proc.stdout, self._free, self._freed, self._replies),
                name=f"encoder {name}",
                daemon=True,
            )
            self._reader.start()
            # a writer dropped without close: its worker ends once its stdin does
            self._finalizer = weakref.finalize(self, _close_stdin, self._proc)
            self._expect("ready", START_TIMEOUT_S)
        finally:
            os.unlink(ring_path)  # both mapped it (or it failed): nothing to leave behind

    def _send(self, *command: Any) -> None:
        stdin = self._proc.stdin
        assert stdin is not None
        try:
            stdin.write((json.dumps(command) + "\n").encode())
            stdin.flush()
        except (BrokenPipeError, ValueError):
            raise self._failed("its process ended") from None

    def _failed(self, why: str) -> FileError:
        return FileError(f"camera {self.name}: the video encoder failed: {why}")

    def _expect(self, kind: str, timeout_s: float | None = None) -> list[Any]:
        """The next reply (``kind``), waiting while the worker lives."""
        waited = 0.0
        while True:
            try:
                message = self._replies.get(timeout=WAIT_S)
            except queue.Empty:
                waited += WAIT_S
                if self._proc.poll() is not None:
                    raise self._failed(f"its process ended ({self._proc.returncode})") from None
                if timeout_s is not None and waited >= timeout_s:
                    raise self._failed(f"no answer in {timeout_s:g} s") from None
                continue
            if message is None:
                raise self._failed("its process ended")
            if message[0] == kind:
                return message

    def open(self, path: Path, fps: int, codec: str) -> None:
        """Start a video at ``path``."""
        self.path = path
        self.dropped = 0
        self._sent = 0
        self._send("open", str(path), fps, codec)

    def add(self, frame: NDArray[np.uint8], *, drop: bool = True) -> bool:
        """Hand one frame over (copied into the ring); without a free slot, drop it (False)
        or, ``drop`` False, wait for one (a recording written faster than real time)."""
        index = self._sent
        self._sent += 1
        while not self._free:
            if drop:
                self.dropped += 1
                return False
            self._freed.clear()
            if not self._free and not self._freed.wait(WAIT_S) and self._proc.poll() is not None:
                raise self._failed(f"its process ended ({self._proc.returncode})")
        slot = self._free.popleft()
        self._ring[slot] = frame
        self._send("frame", slot, index)
        return True

    def finish(self) -> EncodedVideo:
        """Wait for the video to be written whole; what it holds."""
        self._send("finish", self._sent)
        done: dict[str, Any] = self._expect("done")[1]
        if done["error"]:
            raise self._failed(str(done["error"]))
        stats = ImageStats()
        stats.histogram = np.asarray(done["histogram"], dtype=np.int64)
        stats.frames = int(done["stats_frames"])
        stats.pixels = int(done["pixels"])
        return EncodedVideo(int(done["frames"]), int(done["filled"]), stats)

    def abandon(self) -> None:
        """Stop the video under way and remove its file."""
        with contextlib.suppress(FileError):
            self._send("abandon")
            self._expect("abandoned", START_TIMEOUT_S)

    def close(self) -> None:
        """End the process (an open video is abandoned)."""
        self._finalizer.detach()
        with contextlib.suppress(FileError):
            self._send("quit")
        if self._proc.stdin is not None:
            with contextlib.suppress(OSError):
                self._proc.stdin.close()
        try:
            self._proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self._proc.kill()
            self._proc.wait()
        self._reader.join(timeout=5)
        if self._proc.stdout is not None:
            self._proc.stdout.close()
        del self._ring
        with contextlib.suppress(BufferError):
            self._mapped.close()
