"""Fixtures: a generated video file stands in for a camera device (read by VideoCapture)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

cv2 = pytest.importorskip("cv2")

FRAMES = 12
SIZE = (160, 120)


def numbered_frame(index: int, size: tuple[int, int] = SIZE) -> np.ndarray:
    """A frame whose brightness says its number (10 * index), so a test can tell frames apart."""
    width, height = size
    return np.full((height, width, 3), 10 * index, dtype=np.uint8)


@pytest.fixture(scope="session")
def video_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """An MJPEG AVI of FRAMES frames of rising brightness."""
    path = tmp_path_factory.mktemp("video") / "camera.avi"
    writer = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"MJPG"), 20.0, SIZE)
    assert writer.isOpened()
    for index in range(FRAMES):
        writer.write(numbered_frame(index))
    writer.release()
    return path
