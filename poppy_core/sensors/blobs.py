"""``BlobDetector``: coloured blobs (a ball, a sticker) in camera frames, by colour filters.

pypot's config entry and names (pypot 5.0.2, ``pypot.sensor.imagefeature.blob``):
``{"type": "BlobDetector", "cameras": ["camera"], "freq": 5.0, "filters": {"R": [150, 255],
"S": [150, 255]}}``; ``filters`` keeps a pixel when each named channel is within its
``[min, max]``: ``R``, ``G``, ``B`` on the frame's colours, ``H``, ``S``, ``V`` on OpenCV's HSV
(hue 0-179, saturation and value 0-255). The register ``blobs`` lists ``Blob``s with
``center`` (x, y pixels) and ``radius`` (pixels), as pypot's.

Where pypot ran a Hough circle transform on the filtered channels, here the pixels every filter
keeps form a mask, cleaned by an opening (5×5), and each connected region of at least
``min_radius`` becomes a blob: its smallest enclosing circle, largest first. A ball seen whole
is a circle either way; a ball half hidden, or a square sticker, is still found.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from poppy_core.errors import SensorError
from poppy_core.sensors.camera import Camera
from poppy_core.sensors.detector import FrameDetector
from poppy_core.sensors.opencv import cv

DEFAULT_BLOB_FREQ_HZ = 5.0
DEFAULT_MIN_RADIUS_PX = 4
CHANNELS = {"B": 0, "G": 1, "R": 2, "H": 0, "S": 1, "V": 2}
"""Channel -> index in OpenCV's BGR frame (R, G, B) or HSV image (H, S, V)."""
TOP = {"H": 179}
"""OpenCV's 8-bit hue runs 0-179; the other channels 0-255."""

Filters = dict[str, tuple[int, int]]


def check_filters(filters: Mapping[str, Sequence[float]], sensor: str = "") -> Filters:
    """``filters`` as ``{channel: (min, max)}`` with integers in the channel's range.

    Raises:
        SensorError: an unknown channel, or bounds that are not ``[min, max]`` within it.
    """
    if not filters:
        raise SensorError(
            f"sensor {sensor!r}: filters must name at least one of R, G, B, H, S, V",
            sensor=sensor,
        )
    checked: Filters = {}
    for channel, bounds in filters.items():
        top = TOP.get(channel, 255)
        if channel not in CHANNELS:
            raise SensorError(
                f"sensor {sensor!r}: unknown filter channel {channel!r} (R, G, B, H, S or V)",
                sensor=sensor,
            )
        values = list(bounds) if isinstance(bounds, list | tuple) else []
        if (
            len(values) != 2
            or not all(isinstance(v, int | float) and math.isfinite(v) for v in values)
            or not 0 <= values[0] <= values[1] <= top
        ):
            raise SensorError(
                f"sensor {sensor!r}: filter {channel} must be [min, max] within 0-{top}",
                sensor=sensor,
            )
        checked[channel] = (int(values[0]), int(values[1]))
    return checked


@dataclass(frozen=True)
class Blob:
    """A blob seen in one frame: ``center`` (x, y) and ``radius`` in pixels."""

    center: tuple[int, int]
    radius: int
    camera: str = ""
    area: int = 0
    """Pixels the filters kept in it."""

    @property
    def json(self) -> dict[str, Any]:
        """pypot's form: ``{"center": (x, y), "radius": r}``."""
        return {"center": self.center, "radius": self.radius}

    def as_dict(self) -> dict[str, Any]:
        """Plain data (JSON): pypot's keys, the camera and the area."""
        return {
            "center": list(self.center),
            "radius": self.radius,
            "camera": self.camera,
            "area": self.area,
        }

    def draw(
        self, image: np.ndarray, color: tuple[int, int, int] = (255, 0, 0), thickness: int = 3
    ) -> None:
        """Circle the blob on ``image`` (BGR), as pypot's ``Blob.draw``."""
        cv().circle(image, self.center, self.radius, color, thickness)


def find_blobs(
    image: np.ndarray, filters: Filters, min_radius: int = DEFAULT_MIN_RADIUS_PX, camera: str = ""
) -> list[Blob]:
    """The blobs of ``image`` (BGR) that every filter keeps, largest first."""
    cv2 = cv()
    keep = np.ones(image.shape[:2], dtype=bool)
    hsv = None
    for channel, (low, high) in filters.items():
        if channel in "RGB":
            values = image[:, :, CHANNELS[channel]]
        else:
            if hsv is None:
                hsv = cv2.cvtColor(image, cv2.COLOR_BGR2HSV)
            values = hsv[:, :, CHANNELS[channel]]
        keep &= (values >= low) & (values <= high)
    mask = keep.astype(np.uint8) * 255
    mask = cv2.morphologyEx(mask, cv2.MORPH_OPEN, np.ones((5, 5), np.uint8))
    contours, _ = cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE)
    blobs = []
    for contour in contours:
        (x, y), radius = cv2.minEnclosingCircle(contour)
        if radius < min_radius:
            continue
        area = int(cv2.contourArea(contour))
        blobs.append(Blob((round(x), round(y)), round(radius), camera, area))
    return sorted(blobs, key=lambda b: (-b.area, b.center))


class BlobDetector(FrameDetector[Blob]):
    """Finds the blobs ``filters`` keep in the latest frames of ``cameras`` at ``freq`` Hz.

    Args:
        name: the sensor's name.
        cameras: the cameras to look through.
        freq: detections per second.
        filters: channel -> ``(min, max)`` (see the module).
        min_radius: smaller blobs are noise (pixels).

    Raises:
        SensorError: bad filters (one line naming the channel).
    """

    registers: ClassVar[tuple[str, ...]] = ("blobs",)
    what: ClassVar[str] = "blobs"

    def __init__(
        self,
        name: str,
        cameras: Sequence[Camera],
        freq: float = DEFAULT_BLOB_FREQ_HZ,
        *,
        filters: Mapping[str, Sequence[float]],
        min_radius: int = DEFAULT_MIN_RADIUS_PX,
    ) -> None:
        self.filters = check_filters(filters, name)
        self.min_radius = min_radius
        super().__init__(name, cameras, freq)

    def find(self, image: np.ndarray, camera: Camera) -> list[Blob]:
        return find_blobs(image, self.filters, self.min_radius, camera.name)

    @property
    def blobs(self) -> list[Blob]:
        """The blobs in the latest frames (the first read starts the detector and waits)."""
        return self.found()
