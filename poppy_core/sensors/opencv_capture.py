"""``OpenCVCamera``: a V4L2 device (index or path) or a video file, grabbed in the background.

The device is opened when the camera is made: a missing or busy one is a one-line
``SensorError`` (``poppy camera``), or, with ``retry_open`` (a robot's camera: an accessory),
the camera starts lost and is opened with backoff once it can be. A video file stands in for a
device (tests, demos): it loops at its end. A device that stops giving frames is lost: reopened
with backoff, it resumes.
"""

from __future__ import annotations

import logging
import os
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from poppy_core import checks
from poppy_core.errors import ArgumentError, SensorError
from poppy_core.sensors.base import SensorLost
from poppy_core.sensors.camera import DEFAULT_FPS, Camera, CameraCalibration
from poppy_core.sensors.opencv import cv

logger = logging.getLogger(__name__)

Source = int | str
MAX_DEVICE_INDEX = 255
"""The largest V4L2 video device number (``/dev/video255``); ``-1`` means the first found."""
Opener = Callable[[Source], Any]
"""Makes a ``cv2.VideoCapture``-like object (``isOpened``, ``read``, ``set``, ``release``)."""


def device_path(source: Source) -> str:
    """The file a source names: ``/dev/video<N>`` for an index, the path itself otherwise."""
    if isinstance(source, int):
        return f"/dev/video{source}" if source >= 0 else "the first camera"
    return source


def why_not_open(source: Source) -> str:
    """The likely reason a source did not open, with what to do (one line)."""
    path = device_path(source)
    if isinstance(source, int) and source < 0:
        return "no camera found: plug one in (`poppy camera list` shows them)"
    if not os.path.exists(path):
        if path.startswith("/dev/"):
            return f"{path} does not exist: plug the camera in (`poppy camera list` shows them)"
        return f"{path} does not exist"
    if not os.access(path, os.R_OK | os.W_OK):
        return f"no permission on {path}: add yourself to the 'video' group and log in again"
    if path.startswith("/dev/"):
        return f"{path} cannot be opened: another program may be using it"
    return f"OpenCV cannot read {path} as a video"


def _default_opener(source: Source) -> Any:
    cv2 = cv()
    if isinstance(source, int) and source < 0:  # OpenCV's own search for -1 may crash: ours
        found = list_devices()
        if not found:
            return cv2.VideoCapture()  # not opened: "no camera found"
        source = int(found[0]["index"])
    device = (isinstance(source, int) and source >= 0) or str(source).startswith("/dev/")
    if device and sys.platform.startswith("linux"):
        return cv2.VideoCapture(source, cv2.CAP_V4L2)  # not GStreamer: it opens slowly
    return cv2.VideoCapture(source)


def parse_source(value: Any, sensor: str) -> Source:
    """A config's ``index``/``device``: an int, a digit string, or a path.

    Raises:
        SensorError: anything else.
    """
    if isinstance(value, bool) or not isinstance(value, int | str) or value == "":
        raise SensorError(
            f"sensor {sensor!r}: the device is an index (0, 1...) or a path (/dev/video0, "
            f"a video file), got {value!r}",
            sensor=sensor,
        )
    source: Source = value
    if isinstance(source, str) and source.strip().lstrip("-").isdigit():
        source = int(source)
    if isinstance(source, int) and source != -1:  # checked before OpenCV sees it (-5 crashed it)
        try:
            checks.count(source, 0, MAX_DEVICE_INDEX, "the device index")
        except ArgumentError as exc:
            raise SensorError(
                f"sensor {sensor!r}: {exc} (-1: the first camera found)", sensor=sensor
            ) from None
    return source


class OpenCVCamera(Camera):
    """A camera OpenCV reads (pypot's ``OpenCVCamera``: ``index``, ``fps``, ``resolution``).

    Args:
        name: the sensor's name.
        index: a device index (``0`` is ``/dev/video0``; ``-1`` the first found), a device path,
            or a video file.
        fps: frames per second grabbed.
        resolution: ``(width, height)`` asked of the device (None: its default).
        calibration: intrinsics for marker poses.
        opener: makes the capture (tests give a wrapper around ``cv2.VideoCapture``).
        retry_open: a device that cannot be opened now is no error: the camera starts lost
            (one WARNING, ``health()``) and is opened with backoff when it appears or is freed.

    Raises:
        SensorError: the device cannot be opened (missing, busy, no permission), one line
            (not with ``retry_open``).
    """

    registers: ClassVar[tuple[str, ...]] = (*Camera.registers, "index")

    def __init__(
        self,
        name: str,
        index: Source = 0,
        fps: float = DEFAULT_FPS,
        resolution: tuple[int, int] | None = None,
        *,
        calibration: CameraCalibration | None = None,
        opener: Opener | None = None,
        retry_open: bool = False,
    ) -> None:
        super().__init__(name, resolution or (640, 480), fps, calibration=calibration)
        self._source = parse_source(index, name)
        self._asked = resolution
        self._opener = opener or _default_opener
        self._is_file = isinstance(self._source, str) and not self._source.startswith("/dev/")
        self._capture: Any = None
        try:
            self._capture = self._open()
        except SensorError as exc:
            if not retry_open:
                raise
            self.begin_lost(self._reason(exc))

    @property
    def index(self) -> Source:
        """The device index or path."""
        return self._source

    @property
    def device(self) -> str:
        """What the camera reads, for messages: ``/dev/video0``, a path."""
        return device_path(self._source)

    def _open(self) -> Any:
        capture = self._opener(self._source)
        if not capture.isOpened():
            capture.release()
            raise SensorError(
                f"camera {self.name!r}: {why_not_open(self._source)}",
                sensor=self.name,
                device=self.device,
            )
        if self._asked is not None and not self._is_file:
            cv2 = cv()
            capture.set(cv2.CAP_PROP_FRAME_WIDTH, self._asked[0])
            capture.set(cv2.CAP_PROP_FRAME_HEIGHT, self._asked[1])
            capture.set(cv2.CAP_PROP_FPS, self.rate_hz)
        return capture

    def grab(self) -> np.ndarray:
        ok, image = self._capture.read()
        if not ok and self._is_file:  # a video file loops
            self._capture.set(cv().CAP_PROP_POS_FRAMES, 0)
            ok, image = self._capture.read()
        if not ok or image is None:
            raise SensorLost(f"{self.device} gave no frame", sensor=self.name, device=self.device)
        if image.ndim == 2:
            image = cv().cvtColor(image, cv().COLOR_GRAY2BGR)
        if self._asked is not None and self._is_file and image.shape[1::-1] != self._asked:
            image = cv().resize(image, self._asked)
        return np.ascontiguousarray(image)

    def reconnect(self) -> None:
        capture, self._capture = self._capture, None
        if capture is not None:
            try:
                capture.release()
            except Exception:
                logger.debug("releasing %s", self.device, exc_info=True)
        try:
            self._capture = self._open()
        except SensorError as exc:  # health's last_error: the reason, not the sensor's name
            raise SensorError(self._reason(exc), sensor=self.name, device=self.device) from None

    def _reason(self, exc: SensorError) -> str:
        return str(exc).removeprefix(f"camera {self.name!r}: ")

    def release(self) -> None:
        if self._capture is not None:
            self._capture.release()


def list_devices(root: str = "/sys/class/video4linux") -> list[dict[str, Any]]:
    """The V4L2 video devices: ``{"device", "index", "name"}`` each, sorted by index.

    A USB camera often shows two nodes (the second gives metadata, not frames).
    """
    base = Path(root)
    found = []
    for entry in sorted(base.glob("video*")) if base.is_dir() else []:
        suffix = entry.name.removeprefix("video")
        if not suffix.isdigit():
            continue
        try:
            label = (entry / "name").read_text(encoding="utf-8").strip()
        except OSError:
            label = ""
        found.append({"device": f"/dev/{entry.name}", "index": int(suffix), "name": label})
    return sorted(found, key=lambda d: int(d["index"]))
