"""A camera's episode as an MP4 (PyAV): AV1 where the build has SVT-AV1, else H.264; yuv420p.

Facts from LeRobot 0.4.4's ``video_utils.py``: libsvtav1 with g=2, crf=30, preset 12, yuv420p,
and what ``get_video_info`` puts in info.json. Frame k is stamped k/fps exactly (time base
1/fps, pts k). ``Mp4File`` encodes where it is called: ``encoder`` runs it in a process of its own;
the threads SVT-AV1 makes real-time (as root) are put back to the normal policy
(``poppy_core.dataset.realtime``).
"""

from __future__ import annotations

import contextlib
import os
from fractions import Fraction
from pathlib import Path
from typing import Any

import av
import numpy as np
from numpy.typing import NDArray

from poppy_core.dataset.realtime import calling_thread_realtime, realtime_threads, undo_realtime
from poppy_core.errors import PoppyError

AV1 = "libsvtav1"
H264 = "libx264"


def pick_codec() -> str:
    """libsvtav1 when this PyAV build can encode it, else libx264."""
    for name in (AV1, H264):
        try:
            av.codec.Codec(name, "w")
        except (av.codec.codec.UnknownCodecError, ValueError):
            continue
        return name
    raise PoppyError("this PyAV build encodes neither AV1 (libsvtav1) nor H.264 (libx264)")


def codec_options(codec: str) -> dict[str, str]:
    """LeRobot's encoder settings: a key frame every 2 frames, crf 30 (and SVT's preset 12)."""
    options = {"g": "2", "crf": "30"}
    if codec == AV1:
        options["preset"] = "12"
    return options


class Mp4File:
    """RGB frames (height x width x 3, uint8) encoded into one MP4 file, frame k at pts k."""

    def __init__(self, path: Path, fps: int, width: int, height: int, codec: str) -> None:
        self.path = path
        self.frames = 0
        # SVT-AV1 prints its banner on stderr unless told otherwise (1: errors only)
        os.environ.setdefault("SVT_LOG", "1")
        self._container: Any = av.open(str(path), "w", format="mp4")
        stream: Any = self._container.add_stream(codec, rate=fps, options=codec_options(codec))
        stream.pix_fmt = "yuv420p"
        stream.width = width
        stream.height = height
        self._stream: Any = stream
        self._time_base = Fraction(1, fps)
        self._realtime_before = frozenset(realtime_threads())

    def _normal_policy(self, always: bool = False) -> None:
        """After the codec opened (the first frame), at the end, or whenever the caller became
        real-time."""
        if always or self.frames <= 1 or calling_thread_realtime():
            undo_realtime(self._realtime_before)

    def encode(self, frame: NDArray[np.uint8]) -> None:
        """The next frame."""
        picture = av.VideoFrame.from_ndarray(frame, format="rgb24")
        picture.pts = self.frames
        picture.time_base = self._time_base
        for packet in self._stream.encode(picture):
            self._container.mux(packet)
        self.frames += 1
        self._normal_policy()

    def finish(self) -> None:
        """Flush the encoder and close the file."""
        try:
            for packet in self._stream.encode(None):
                self._container.mux(packet)
        finally:
            self.close()
            self._normal_policy(always=True)

    def close(self) -> None:
        with contextlib.suppress(av.error.FFmpegError, OSError):
            self._container.close()


ENCODING_ERRORS = (av.error.FFmpegError, ValueError, OSError)


def video_info(path: Path, fps: int) -> dict[str, Any]:
    """What LeRobot's ``get_video_info`` records of a video, read from the file."""
    with av.open(str(path), "r") as container:
        stream: Any = container.streams.video[0]
        return {
            "video.height": stream.height,
            "video.width": stream.width,
            "video.codec": stream.codec_context.codec.canonical_name,
            "video.pix_fmt": stream.pix_fmt,
            "video.is_depth_map": False,
            "video.fps": fps,
            "video.channels": 3,
            "has_audio": len(container.streams.audio) > 0,
        }


class JpegEncoder:
    """RGB frames as JPEG bytes (PyAV's MJPEG encoder): a video's frames as single pictures,
    for the exports (Foxglove's compressed images)."""

    def __init__(self) -> None:
        self._context: Any = None
        self._size: tuple[int, int] | None = None
        self._pts = 0

    def encode(self, frame: NDArray[np.uint8]) -> bytes:
        """``frame`` (height x width x 3, RGB) as one JPEG picture."""
        height, width = frame.shape[:2]
        if self._size != (height, width):
            context: Any = av.CodecContext.create("mjpeg", "w")
            context.width, context.height = width, height
            context.pix_fmt = "yuvj420p"
            context.time_base = Fraction(1, 30)
            self._context, self._size = context, (height, width)
        picture = av.VideoFrame.from_ndarray(frame, format="rgb24").reformat(format="yuvj420p")
        picture.pts = self._pts  # the encoder refuses a picture without a new pts
        self._pts += 1
        return b"".join(bytes(packet) for packet in self._context.encode(picture))
