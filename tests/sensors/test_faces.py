"""Faces: found in a still image (scikit-image's astronaut), through a camera, from a config."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

from poppy_core.errors import ArgumentError, ConfigError, SensorError
from poppy_core.sensors import (
    NOT_YET,
    SUPPORTED_TYPES,
    DummyCamera,
    FaceDetector,
    FaceFinder,
    build_sensors,
    opencv_camera,
)
from poppy_core.sensors.opencv_capture import OpenCVCamera
from tests.helpers.configs import checked_sensors
from tests.helpers.waiting import eventually

cv2 = pytest.importorskip("cv2")
skimage_data = pytest.importorskip("skimage.data")

FACE_BOX = (170, 50, 290, 175)
"""Where the astronaut's face is in skimage's 512×512 image: x0, y0, x1, y1 (pixels)."""


def astronaut_bgr() -> np.ndarray:
    return np.ascontiguousarray(cv2.cvtColor(skimage_data.astronaut(), cv2.COLOR_RGB2BGR))


def inside(point: tuple[float, float], box: tuple[float, float, float, float]) -> bool:
    return box[0] <= point[0] <= box[2] and box[1] <= point[1] <= box[3]


@pytest.fixture(scope="module")
def finder() -> FaceFinder:
    return FaceFinder()


def test_the_astronauts_face_is_found(finder: FaceFinder) -> None:
    (face,) = finder.find(astronaut_bgr(), camera="camera")
    assert inside(face.center, FACE_BOX), face
    assert 60 <= face.size <= 140
    x, y, w, h = face.rect
    assert (x + w / 2, y + h / 2) == pytest.approx(face.center, abs=1) and w == h
    assert face.hits >= 6
    u, v = face.center
    assert face.position == pytest.approx((2 * u / 512 - 1, 2 * v / 512 - 1))
    data = face.as_dict()
    assert set(data) == {"center", "rect", "position", "camera", "hits"}
    assert data["camera"] == "camera" and data["rect"] == list(face.rect)


@pytest.mark.parametrize("scale", [0.6, 1.0, 1.6])
def test_the_face_is_found_at_other_sizes_and_places(finder: FaceFinder, scale: float) -> None:
    image = astronaut_bgr()
    size = round(512 * scale)
    resized = cv2.resize(image, (size, size))
    canvas = np.full((max(size, 480), max(size, 640) + 100, 3), 200, dtype=np.uint8)
    canvas[:size, 100 : 100 + size] = resized  # moved right by 100 px
    faces = finder.find(canvas)
    box = tuple(v * scale + (100 if i % 2 == 0 else 0) for i, v in enumerate(FACE_BOX))
    assert faces and inside(faces[0].center, box), (faces, box)  # the surest first


@pytest.mark.parametrize("picture", ["coffee", "chelsea", "rocket", "blank", "grey"])
def test_no_face_where_there_is_none(finder: FaceFinder, picture: str) -> None:
    if picture == "blank":
        image = np.zeros((480, 640, 3), dtype=np.uint8)
    elif picture == "grey":
        image = cv2.cvtColor(skimage_data.camera(), cv2.COLOR_GRAY2BGR)[:, :, 0]  # grey frames too
        image = image[:100, :100]  # the sky above the cameraman
    else:
        image = cv2.cvtColor(getattr(skimage_data, picture)(), cv2.COLOR_RGB2BGR)
    assert finder.find(image) == []


def test_bad_sizes_are_refused() -> None:
    for size in (4, 0, -1, 2.5, True, 10**9):
        with pytest.raises(ArgumentError, match="min_size"):
            FaceFinder(min_size=size)  # type: ignore[arg-type]
    with pytest.raises(SensorError, match="no cascade file"):
        FaceFinder(cascade="/nonexistent/cascade.xml")


class StillCamera(DummyCamera):
    """A camera that shows one picture."""

    def __init__(self, image: np.ndarray) -> None:
        super().__init__("camera", (image.shape[1], image.shape[0]), 30.0)
        self.image = image

    def grab(self) -> np.ndarray:
        return self.image


def test_the_face_detector_sees_the_face_through_its_camera() -> None:
    camera = StillCamera(astronaut_bgr())
    with camera, FaceDetector("face_detector", [camera], freq=10.0) as detector:
        assert detector.registers == ("faces",)
        (face,) = detector.faces
        assert inside(face.center, FACE_BOX) and face.camera == "camera"
        assert detector.read("faces") == [face]
        assert detector.detect() == [face]
        health = detector.health()
        assert health.ok and health.running and health.kind == "FaceDetector"


def write_video(path: Path) -> None:
    writer = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"MJPG"), 20.0, (512, 512))
    for _ in range(5):
        writer.write(astronaut_bgr())
    writer.release()


def test_a_face_detector_on_a_video_file_from_a_config(tmp_path: Path) -> None:
    path = tmp_path / "astronaut.avi"
    write_video(path)
    section: dict[str, Any] = {
        "camera": {"type": "OpenCVCamera", "index": str(path), "fps": 20.0},
        "face_detector": {
            "type": "FaceDetector",
            "cameras": ["camera"],
            "freq": 4.0,
            "min_size": 30,
        },
    }
    sensors = build_sensors(checked_sensors(section), opencv_camera)
    try:
        detector = sensors["face_detector"]
        assert isinstance(detector, FaceDetector) and detector.rate_hz == 4.0
        assert detector.finder.min_size == 30
        faces = detector.read("faces")
        assert len(faces) == 1 and inside(faces[0].center, FACE_BOX)
    finally:
        for sensor in reversed(list(sensors.values())):
            sensor.close()


def test_face_detectors_are_no_longer_refused() -> None:
    assert "FaceDetector" in SUPPORTED_TYPES and "FaceDetector" not in NOT_YET


@pytest.mark.parametrize(
    ("spec", "field"),
    [
        ({"min_size": 3}, "face_detector.min_size"),
        ({"min_size": "big"}, "face_detector.min_size"),
        ({"cascade": 7}, "face_detector.cascade"),
        ({"cameras": ["nothing"]}, "face_detector.cameras"),
        ({"freq": 0}, "face_detector.freq"),
    ],
)
def test_bad_face_detector_entries_name_their_field(spec: dict[str, Any], field: str) -> None:
    entry = {"type": "FaceDetector", "cameras": ["camera"], **spec}
    with pytest.raises(ConfigError) as caught:
        checked_sensors({"camera": {"type": "DummyCamera"}, "face_detector": entry})
    assert caught.value.field == f"sensors.{field}"


def test_a_face_detector_on_a_camera_plugged_in_later(tmp_path: Path) -> None:
    device = tmp_path / "video0.avi"
    camera = OpenCVCamera("camera", str(device), fps=20.0, retry_open=True)
    with camera, FaceDetector("face_detector", [camera], freq=5.0) as detector:
        assert not camera.health().connected
        with pytest.raises(SensorError) as caught:
            detector.wait_first(1.0)  # no frame: one line saying why (as reading faces)
        assert "\n" not in str(caught.value)
        part = tmp_path / "writing.avi"
        write_video(part)
        part.rename(device)  # plugged in
        assert eventually(lambda: bool(detector.detect()), timeout_s=20)
        assert eventually(lambda: len(detector.faces) == 1)
        assert inside(detector.faces[0].center, FACE_BOX)
        assert camera.health().connected and detector.health().ok
