"""Cameras: the ``Camera`` contract (latest frame, resolution, fps), a blank ``DummyCamera``.

A frame is a numpy array ``(height, width, 3)`` of ``uint8`` in OpenCV's BGR order, as pypot's
cameras give (``cv2.imwrite("f.png", robot.camera.frame)`` works). ``camera.frame`` is a copy
of the latest frame (draw on it freely); ``latest()`` is the shared, read-only one.
``encoded(frame, ".jpg", q)`` encodes a frame once for every reader asking the same format and
quality (through ``encode``, which a camera with its own encoder overrides); ``await
wait_frame(after)`` waits for a new frame in an event loop, holding no thread.
"""

from __future__ import annotations

import asyncio
import concurrent.futures
import contextlib
import math
import threading
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from poppy_core.errors import SensorError
from poppy_core.sensors.base import FIRST_VALUE_TIMEOUT_S, Sensor
from poppy_core.sensors.opencv import encode_image

DEFAULT_RESOLUTION = (640, 480)
DEFAULT_FPS = 20.0
JPEG_QUALITY = 80
"""The JPEG quality every reader of a frame gets unless it asks another (the MJPEG viewers,
snapshots, ROS 2, Foxglove): one encoding of each frame serves them all."""


@dataclass(frozen=True)
class Frame:
    """One frame and when it was taken: ``number`` counts frames from 1."""

    image: np.ndarray
    number: int
    time_s: float


@dataclass(frozen=True)
class CameraCalibration:
    """Pinhole intrinsics (pixels) and lens distortion, as OpenCV's ``solvePnP`` takes them."""

    camera_matrix: np.ndarray
    dist_coeffs: np.ndarray

    @classmethod
    def from_fov(cls, width: int, height: int, fovy_deg: float) -> CameraCalibration:
        """An ideal camera (no distortion, square pixels) of vertical field of view ``fovy_deg``."""
        focal = (height / 2.0) / math.tan(math.radians(fovy_deg) / 2.0)
        matrix = np.array([[focal, 0.0, width / 2.0], [0.0, focal, height / 2.0], [0, 0, 1.0]])
        return cls(matrix, np.zeros(5))

    @classmethod
    def from_config(cls, data: Any, sensor: str) -> CameraCalibration:
        """From ``{"camera_matrix": [[fx, 0, cx], [0, fy, cy], [0, 0, 1]], "dist_coeffs": [...]}``.

        Raises:
            SensorError: the shape is not that.
        """
        try:
            matrix = np.asarray(data["camera_matrix"], dtype=float)
            dist = np.asarray(data.get("dist_coeffs", [0.0] * 5), dtype=float).ravel()
        except (TypeError, KeyError, ValueError, AttributeError):
            matrix = np.zeros(0)
            dist = np.zeros(0)
        if (
            matrix.shape != (3, 3)
            or dist.size not in (4, 5, 8, 12, 14)
            or not np.all(np.isfinite(matrix))
        ):
            raise SensorError(
                f"sensor {sensor!r}: calibration must be {{camera_matrix: 3x3 numbers, "
                "dist_coeffs: 4, 5, 8, 12 or 14 numbers}} (OpenCV's calibrateCamera output)",
                sensor=sensor,
            )
        return cls(matrix, dist)

    def as_dict(self) -> dict[str, Any]:
        """Plain data (JSON)."""
        return {
            "camera_matrix": self.camera_matrix.tolist(),
            "dist_coeffs": self.dist_coeffs.tolist(),
        }


def check_resolution(value: Any, sensor: str) -> tuple[int, int]:
    """``[width, height]`` as two positive ints.

    Raises:
        SensorError: anything else.
    """
    if (
        isinstance(value, Sequence)
        and len(value) == 2
        and all(isinstance(v, int) and not isinstance(v, bool) and 0 < v <= 8192 for v in value)
    ):
        return int(value[0]), int(value[1])
    raise SensorError(
        f"sensor {sensor!r}: resolution must be [width, height] in pixels, got {value!r}",
        sensor=sensor,
    )


class Camera(Sensor):
    """A sensor whose value is an image; subclasses implement ``grab``.

    Args:
        name: the sensor's name.
        resolution: ``(width, height)`` asked for.
        fps: frames per second grabbed once started.
        calibration: intrinsics for marker poses (None: poses are not computed).
    """

    registers: ClassVar[tuple[str, ...]] = ("frame", "resolution", "fps")

    def __init__(
        self,
        name: str,
        resolution: tuple[int, int] = DEFAULT_RESOLUTION,
        fps: float = DEFAULT_FPS,
        *,
        calibration: CameraCalibration | None = None,
    ) -> None:
        super().__init__(name, fps)
        self._resolution = check_resolution(list(resolution), name)
        self.calibration = calibration
        self._latest: Frame | None = None
        self._new_frame = threading.Condition()
        self._loops: dict[asyncio.AbstractEventLoop, asyncio.Future[None]] = {}
        """Per event loop with coroutines waiting for a frame: one future the next frame settles."""
        self._async_waiting = 0
        self._encodings: dict[tuple[str, int], concurrent.futures.Future[bytes]] = {}
        """The latest frame's encodings by (format, quality), its number in ``_encoded_number``."""
        self._encoded_number = 0
        self._encodings_lock = threading.Lock()

    def grab(self) -> np.ndarray:
        """Take one BGR frame (called in the camera's thread).

        Raises:
            SensorLost: the device went away.
        """
        raise NotImplementedError

    def update(self) -> None:
        image = self.grab()
        image.flags.writeable = False
        with self._new_frame:
            number = 1 if self._latest is None else self._latest.number + 1
            self._latest = Frame(image, number, self._clock())
            self._new_frame.notify_all()
            self._wake_loops()

    def wake(self) -> None:
        with self._new_frame:
            self._new_frame.notify_all()
            self._wake_loops()

    def _wake_loops(self) -> None:
        """Settle each waiting loop's future in its own thread (called holding ``_new_frame``)."""
        loops, self._loops = self._loops, {}
        for loop, future in loops.items():
            with contextlib.suppress(RuntimeError):  # a loop closed: nobody waits there now
                loop.call_soon_threadsafe(_settle, future)

    # -- registers -----------------------------------------------------------------------------

    @property
    def frame(self) -> np.ndarray:
        """A copy of the latest frame (the first read starts the camera and waits for a frame).

        Raises:
            SensorError: no frame came in time.
        """
        return self.latest().image.copy()

    @property
    def resolution(self) -> list[int]:
        """``[width, height]`` of the frames (the asked one before the first frame)."""
        latest = self._latest
        if latest is None:
            return list(self._resolution)
        height, width = latest.image.shape[:2]
        return [int(width), int(height)]

    @property
    def fps(self) -> float:
        """Frames per second grabbed."""
        return self.rate_hz

    # -- for readers that want no copy ----------------------------------------------------------

    def latest(self, timeout_s: float = FIRST_VALUE_TIMEOUT_S) -> Frame:
        """The latest frame, shared and read-only (starts the camera; the first call waits).

        Raises:
            SensorError: no frame came in time.
        """
        latest = self._latest
        if latest is not None:
            return latest
        self.wait_first(timeout_s)
        latest = self._latest
        assert latest is not None
        return latest

    def next_frame(
        self, after: int = 0, timeout_s: float = FIRST_VALUE_TIMEOUT_S, *, start: bool = True
    ) -> Frame:
        """The first frame whose number is above ``after`` (0: any; -1: one grabbed from now on).

        ``start=False`` (a reader that only follows a camera someone else opened) never starts
        the camera: a camera not running raises at once.

        Raises:
            SensorError: none came within ``timeout_s``, or the camera is not running
                (``start=False``).
        """
        if start:
            self.start()
        elif not self.running:
            raise SensorError(f"camera {self.name!r} is not running", sensor=self.name)
        with self._new_frame:
            if after < 0:
                after = 0 if self._latest is None else self._latest.number
            ok = self._new_frame.wait_for(
                lambda: self._fatal or (self._latest is not None and self._latest.number > after),
                timeout_s,
            )
            if self._fatal:
                raise SensorError(f"camera {self.name!r}: {self._fatal}", sensor=self.name)
            if not ok or self._latest is None:
                why = f" ({self.health().last_error})" if self.health().last_error else ""
                raise SensorError(
                    f"camera {self.name!r} gave no new frame in {timeout_s:g} s{why}",
                    sensor=self.name,
                )
            return self._latest

    async def wait_frame(self, after: int = 0, timeout_s: float = FIRST_VALUE_TIMEOUT_S) -> Frame:
        """``next_frame`` for a coroutine: awaits in the event loop, holding no thread.

        However many coroutines of one loop wait, the camera's thread wakes that loop once a
        frame (``loop.call_soon_threadsafe``).

        Raises:
            SensorError: none came within ``timeout_s``, or the camera failed for good.
        """
        loop = asyncio.get_running_loop()
        deadline = loop.time() + timeout_s
        self.start()
        while True:
            with self._new_frame:
                latest = self._latest
                if self._fatal:
                    raise SensorError(f"camera {self.name!r}: {self._fatal}", sensor=self.name)
                if after < 0:
                    after = 0 if latest is None else latest.number
                if latest is not None and latest.number > after:
                    return latest
                future = self._loops.get(loop)
                if future is None:
                    future = self._loops[loop] = loop.create_future()
            remaining = deadline - loop.time()
            if remaining <= 0:
                why = f" ({self.health().last_error})" if self.health().last_error else ""
                raise SensorError(
                    f"camera {self.name!r} gave no new frame in {timeout_s:g} s{why}",
                    sensor=self.name,
                )
            with self._new_frame:
                self._async_waiting += 1
            try:
                # asyncio.wait neither cancels the loop's shared future on a timeout nor when
                # this waiter is cancelled (its client left); a timeout is said on the next turn
                await asyncio.wait((future,), timeout=remaining)
            finally:
                with self._new_frame:
                    self._async_waiting -= 1

    def async_waiters(self) -> int:
        """How many coroutines are in ``wait_frame`` now (a stream whose client left is not)."""
        return self._async_waiting

    # -- one encoding per frame, format and quality ---------------------------------------------

    def encode(self, image: np.ndarray, ext: str, quality: int) -> bytes:
        """``image`` as ``.jpg`` or ``.png`` bytes (a camera with its own encoder overrides this).

        Raises:
            SensorError: an unknown format, or the frame could not be encoded.
        """
        return encode_image(image, ext, quality)

    def encoded(self, frame: Frame, ext: str = ".jpg", quality: int = JPEG_QUALITY) -> bytes:
        """``frame`` as ``.jpg`` or ``.png`` bytes, encoded once for the latest frame's readers.

        The first reader asking a (format, quality) of the latest frame encodes it; readers
        asking meanwhile wait for that encoding instead of doing their own. An older frame is
        encoded for its reader alone.

        Raises:
            SensorError: an unknown format, or the frame could not be encoded.
        """
        future, mine = self._claim(frame, ext, quality)
        if mine:
            self._encode_into(future, frame, ext, quality)
        return future.result()

    async def encoded_async(
        self, frame: Frame, ext: str = ".jpg", quality: int = JPEG_QUALITY
    ) -> bytes:
        """``encoded`` for a coroutine: one worker thread encodes, every reader awaits it
        holding no thread; a reader cancelled meanwhile (its client left) leaves the encoding
        to the others."""
        future, mine = self._claim(frame, ext, quality)
        if mine:
            # not awaited by this reader: its cancellation must not cancel (or, still queued,
            # drop) the encoding the other readers wait for
            try:
                asyncio.get_running_loop().run_in_executor(
                    None, self._encode_into, future, frame, ext, quality
                )
            except RuntimeError:  # the loop's executor is shut down: encode here
                self._encode_into(future, frame, ext, quality)
        if future.done():  # the usual case: another viewer's encoding of this frame is ready
            return future.result()
        # the future runs (see _claim): a cancelled reader's wrap cannot cancel it for all
        return await asyncio.wrap_future(future)

    def _claim(
        self, frame: Frame, ext: str, quality: int
    ) -> tuple[concurrent.futures.Future[bytes], bool]:
        """The encoding of ``frame`` to wait for, and whether the caller must make it.

        The future is marked running at once: nobody can cancel it (``asyncio.wrap_future``
        passes a waiter's cancellation on to a pending one, which would leave every reader of
        this frame a cancelled encoding).
        """
        key = (ext, quality)
        with self._encodings_lock:
            if frame.number > self._encoded_number:
                self._encodings = {}
                self._encoded_number = frame.number
            future = self._encodings.get(key) if frame.number == self._encoded_number else None
            if future is not None:
                return future, False
            future = concurrent.futures.Future()
            future.set_running_or_notify_cancel()
            if frame.number == self._encoded_number:  # an older frame: its reader's alone
                self._encodings[key] = future
            return future, True

    def _encode_into(
        self, future: concurrent.futures.Future[bytes], frame: Frame, ext: str, quality: int
    ) -> None:
        """Settle ``future`` with the encoding (or its error, which the next reader retries)."""
        try:
            data = self.encode(frame.image, ext, quality)
        except BaseException as exc:
            with self._encodings_lock:
                if self._encodings.get((ext, quality)) is future:
                    del self._encodings[(ext, quality)]
            future.set_exception(exc)
            if not isinstance(exc, Exception):
                raise
            return
        future.set_result(data)


def _settle(future: asyncio.Future[None]) -> None:
    if not future.done():
        future.set_result(None)


class DummyCamera(Camera):
    """Black frames of the asked resolution (pypot's ``camera='dummy'``; ideal simulation)."""

    def __init__(
        self,
        name: str,
        resolution: tuple[int, int] = DEFAULT_RESOLUTION,
        fps: float = DEFAULT_FPS,
        **_ignored: Any,
    ) -> None:
        super().__init__(name, resolution, fps)
        width, height = self._resolution
        self._black = np.zeros((height, width, 3), dtype=np.uint8)

    def grab(self) -> np.ndarray:
        return self._black
