"""Faces in a frame (``FaceFinder``) and in a camera's frames, in the background (``FaceDetector``).

pypot's ``FaceDetector`` (``cameras``, ``freq``; register ``faces``, each with ``center`` and
``rect``) ran OpenCV's Haar cascade. OpenCV 5 (the version installed with poppy) no longer ships
Haar cascades nor ``CascadeClassifier``; scikit-image ships OpenCV's LBP frontal-face cascade and
a detector for it (``skimage.feature.Cascade``), so faces need the ``faces`` extra
(``pip install 'poppy[faces]'``). It is imported on first use.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from poppy_core.checks import count
from poppy_core.errors import MissingExtraError, SensorError
from poppy_core.extras import require
from poppy_core.sensors.camera import Camera
from poppy_core.sensors.detector import FrameDetector
from poppy_core.sensors.opencv import cv

DEFAULT_FACE_FREQ_HZ = 2.0
DEFAULT_MIN_SIZE_PX = 24
"""Smallest face looked for, in pixels of the frame as searched (``WORK_WIDTH_PX`` wide at most)."""
MIN_FACE_PX, MAX_FACE_PX = 8, 4096
WORK_WIDTH_PX = 320
"""Frames wider than this are shrunk before the search (the cascade's cost grows with pixels)."""
SCALE_FACTOR = 1.2
MIN_NEIGHBOURS = 6
"""Search windows that must find a face (fewer: a false alarm)."""


@dataclass(frozen=True)
class Face:
    """A face seen in one frame: ``rect`` (x, y, width, height) and ``center`` in pixels."""

    rect: tuple[int, int, int, int]
    center: tuple[float, float]
    position: tuple[float, float]
    """Centre normalised to -1..1 of the frame (x right, y down), as a marker's ``position``."""
    camera: str = ""
    hits: int = 0
    """Search windows that found it: the more, the surer (faces are listed most sure first)."""

    @property
    def size(self) -> int:
        """Width of the face's square, in pixels."""
        return self.rect[2]

    def as_dict(self) -> dict[str, Any]:
        """Plain data (JSON), with pypot's ``center`` and ``rect``."""
        return {
            "center": [round(v, 1) for v in self.center],
            "rect": list(self.rect),
            "position": [round(v, 4) for v in self.position],
            "camera": self.camera,
            "hits": self.hits,
        }


def _cascade(path: str | None) -> Any:
    try:
        require("skimage", extra="faces", feature="face detection")
    except MissingExtraError as exc:
        raise SensorError(str(exc)) from None
    from skimage import data
    from skimage.feature import Cascade

    shipped: Any = data  # untyped
    chosen = path or str(shipped.lbp_frontal_face_cascade_filename())
    if not Path(chosen).is_file():
        raise SensorError(f"no cascade file {chosen!r} (an OpenCV LBP cascade XML)")
    try:
        return Cascade(chosen)
    except Exception as exc:
        raise SensorError(f"{chosen} is not an OpenCV LBP cascade: {exc}") from exc


class FaceFinder:
    """Finds frontal faces in frames, surest first (no thread: ``FaceDetector`` runs one).

    Args:
        min_size: smallest face looked for, pixels (in the frame as searched).
        cascade: an OpenCV LBP cascade XML (None: scikit-image's frontal face).

    Raises:
        SensorError: no scikit-image (the extra is named), a bad cascade.
        ArgumentError: a size that is not a whole number of pixels from 8 to 4096.
    """

    def __init__(self, min_size: int = DEFAULT_MIN_SIZE_PX, cascade: str | None = None) -> None:
        self.min_size = count(min_size, MIN_FACE_PX, MAX_FACE_PX, "min_size")
        self._cascade = _cascade(cascade)

    def find(self, frame: np.ndarray, camera: str = "") -> list[Face]:
        """Every face in ``frame`` (BGR or grey), the surest first."""
        cv2 = cv()
        grey = frame if frame.ndim == 2 else cv2.cvtColor(frame, cv2.COLOR_BGR2GRAY)
        height, width = grey.shape[:2]
        scale = min(1.0, WORK_WIDTH_PX / width)
        if scale < 1.0:
            grey = cv2.resize(
                grey, (round(width * scale), round(height * scale)), interpolation=cv2.INTER_AREA
            )
        side = min(grey.shape[:2])
        if side < self.min_size:
            return []
        windows = self._cascade.detect_multi_scale(
            img=grey.astype(np.float32) / 255.0,
            scale_factor=SCALE_FACTOR,
            step_ratio=1,
            min_size=(self.min_size, self.min_size),
            max_size=(side, side),
            min_neighbor_number=1,
            intersection_score_threshold=2.0,  # never: every window comes back, grouped below
        )
        faces = []
        for (x, y, w), hits in _group([(d["c"], d["r"], d["width"]) for d in windows]):
            x, y, w = x / scale, y / scale, w / scale
            cx, cy = x + w / 2, y + w / 2
            faces.append(
                Face(
                    (round(x), round(y), round(w), round(w)),
                    (cx, cy),
                    (2 * cx / width - 1, 2 * cy / height - 1),
                    camera,
                    hits,
                )
            )
        return faces


Window = tuple[float, float, float]
"""A square search window: left, top, side (pixels)."""


def _group(windows: list[tuple[int, int, int]]) -> list[tuple[Window, int]]:
    """Windows that found the same face, averaged: ``(window, hits)``, most hits first.

    A face is found by many windows of nearby places and sizes; a false alarm by few. Groups of
    fewer than ``MIN_NEIGHBOURS`` windows are dropped, and a group centred inside a stronger one
    (a part of the same face) too.
    """
    groups: list[list[tuple[int, int, int]]] = []
    for x, y, w in sorted(windows, key=lambda win: -win[2]):
        for group in groups:
            gx, gy, gw = np.mean(group, axis=0)
            dx, dy = x + w / 2 - gx - gw / 2, y + w / 2 - gy - gw / 2
            if max(abs(dx), abs(dy)) <= 0.3 * gw and gw / 1.5 <= w <= gw * 1.5:
                group.append((x, y, w))
                break
        else:
            groups.append([(x, y, w)])
    kept: list[tuple[Window, int]] = []
    for group in sorted(groups, key=len, reverse=True):
        if len(group) < MIN_NEIGHBOURS:
            break
        gx, gy, gw = (float(v) for v in np.mean(group, axis=0))
        cx, cy = gx + gw / 2, gy + gw / 2
        if any(kx <= cx <= kx + kw and ky <= cy <= ky + kw for (kx, ky, kw), _ in kept):
            continue
        kept.append(((gx, gy, gw), len(group)))
    return kept


class FaceDetector(FrameDetector[Face]):
    """Detects faces in the latest frames of ``cameras`` at ``freq`` Hz (pypot's ``FaceDetector``).

    Args:
        name: the sensor's name (``face_detector``).
        cameras: the cameras to look through.
        freq: detections per second.
        min_size: smallest face looked for, pixels (frames are searched 320 pixels wide).
        cascade: an OpenCV LBP cascade XML (None: scikit-image's frontal face).

    Raises:
        SensorError: no scikit-image (the extra is named), no camera, a bad cascade.
        ArgumentError: a bad size.
    """

    registers: ClassVar[tuple[str, ...]] = ("faces",)
    what: ClassVar[str] = "faces"

    def __init__(
        self,
        name: str,
        cameras: Sequence[Camera],
        freq: float = DEFAULT_FACE_FREQ_HZ,
        *,
        min_size: int = DEFAULT_MIN_SIZE_PX,
        cascade: str | None = None,
    ) -> None:
        super().__init__(name, cameras, freq)
        self.finder = FaceFinder(min_size, cascade)

    def find(self, image: np.ndarray, camera: Camera) -> list[Face]:
        return self.finder.find(image, camera.name)

    @property
    def faces(self) -> list[Face]:
        """The faces in the latest frames, the surest first (the first read starts the detector
        and waits).

        Raises:
            SensorError: no detection ran in time (a camera gives no frame).
        """
        return sorted(self.found(), key=lambda f: -f.hits)
