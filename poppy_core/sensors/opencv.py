"""OpenCV imported on first use, its log quietened, typed loosely; image encoding."""

from __future__ import annotations

import os
from typing import Any

from poppy_core.errors import MissingExtraError, SensorError
from poppy_core.extras import require


def cv() -> Any:
    """The ``cv2`` module (import costs ~0.2 s, so the CLI and ``import poppy_core`` defer it).

    Raises:
        SensorError: OpenCV is not installed.
    """
    # OpenCV prints its own warnings (e.g. "can't open camera by index") on stderr unless told.
    os.environ.setdefault("OPENCV_LOG_LEVEL", "ERROR")
    try:
        require("cv2", extra="vision", feature="cameras")
    except MissingExtraError as exc:
        raise SensorError(str(exc), sensor=None) from None
    import cv2

    return cv2


def encode_image(frame: Any, ext: str, quality: int = 85) -> bytes:
    """``frame`` (BGR) encoded as ``.png`` or ``.jpg`` bytes.

    Raises:
        SensorError: an unknown format, or OpenCV could not encode the frame.
    """
    cv2 = cv()
    if ext not in (".png", ".jpg", ".jpeg"):
        raise SensorError(f"unknown image format {ext!r} (use .png or .jpg)")
    params = [int(cv2.IMWRITE_JPEG_QUALITY), quality] if ext != ".png" else []
    ok, data = cv2.imencode(ext, frame, params)
    if not ok:
        raise SensorError(f"OpenCV could not encode a {frame.shape} frame as {ext}")
    return bytes(data.tobytes())
