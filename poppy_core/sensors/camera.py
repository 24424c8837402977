"""Cameras: the ``Camera`` contract (latest frame, resolution, fps), a blank ``DummyCamera``.

A frame is a numpy array ``(height, width, 3)`` of ``uint8`` in OpenCV's BGR order, as pypot's
cameras give (``cv2.imwrite("f.png", robot.camera.frame)`` works). ``camera.frame`` is a copy
of the latest frame (draw on it freely); ``latest()`` is the shared, read-only one.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from poppy_core.errors import SensorError
from poppy_core.sensors.base import FIRST_VALUE_TIMEOUT_S, Sensor

DEFAULT_RESOLUTION = (640, 480)
DEFAULT_FPS = 20.0


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

    def wake(self) -> None:
        with self._new_frame:
            self._new_frame.notify_all()

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
