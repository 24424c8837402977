"""PoseSkeleton with MediaPipe (its own venv, ``python -m poppy_core.sensors.pose_venv``) on
scikit-image's ``astronaut()``: the joints where she is, left and right the right way round."""

from __future__ import annotations

import os
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from poppy_core.sensors import DummyCamera, PoseSkeleton
from poppy_core.sensors.config import build_sensors, opencv_camera
from poppy_core.sensors.pose import PoseWorker, skeleton_from_landmarks
from tests.helpers.cli import command_env
from tests.helpers.configs import checked_sensors
from tests.helpers.pose import mediapipe_python
from tests.helpers.waiting import eventually

cv2 = pytest.importorskip("cv2")
skimage_data = pytest.importorskip("skimage.data")

FACE_BOX = (170, 50, 290, 175)
"""Where her face is in the 512x512 picture (x0, y0, x1, y1), as tests/sensors/test_faces.py."""


def astronaut_bgr() -> np.ndarray:
    return np.ascontiguousarray(skimage_data.astronaut()[:, :, ::-1])


def check_astronaut(skeleton: Any) -> None:
    """Her joints in the 512x512 picture: the head in her face, her left shoulder on the
    picture's right, the elbows below the shoulders, the hips below the picture."""
    x0, y0, x1, y1 = FACE_BOX
    head = skeleton.head.pixel_coordinate
    assert x0 <= head.x <= x1 and y0 <= head.y <= y1, head
    left, right = skeleton.shoulder_left.pixel_coordinate, skeleton.shoulder_right.pixel_coordinate
    assert 290 < left.x < 400 and 20 < right.x < 170, (left, right)  # her left: our right
    assert y1 < left.y < 330 and y1 < right.y < 330, (left, right)
    for side in ("left", "right"):
        elbow = getattr(skeleton, f"elbow_{side}").pixel_coordinate
        shoulder = getattr(skeleton, f"shoulder_{side}").pixel_coordinate
        assert elbow.y > shoulder.y + 60, (side, elbow, shoulder)
    assert skeleton.hip_center.pixel_coordinate.y > 450
    # the Kinect's axes: x to the camera's left, so her left shoulder has the smaller x; y up
    assert skeleton.shoulder_left.position.x < skeleton.shoulder_right.position.x
    assert skeleton.head.position.y > skeleton.shoulder_center.position.y > 0.2
    assert skeleton.hip_center.position == pytest.approx(
        (0.0, 0.0, 0.0), abs=0.02
    )  # MediaPipe's origin


def test_the_worker_finds_her_and_nobody_in_a_blank_frame() -> None:
    worker = PoseWorker(mediapipe_python(), static=True)
    try:
        assert worker.version == "0.10.21"
        answer = worker.estimate(skimage_data.astronaut())  # RGB
        assert answer is not None and len(answer["landmarks"]) == 33
        check_astronaut(skeleton_from_landmarks(answer["landmarks"], answer["world"], (512, 512)))
        assert worker.estimate(np.zeros((240, 320, 3), np.uint8)) is None
    finally:
        worker.close()


class StillCamera(DummyCamera):
    """A camera that shows one picture."""

    def __init__(self, image: np.ndarray) -> None:
        super().__init__("camera", (image.shape[1], image.shape[0]), 30.0)
        self.image = image

    def grab(self) -> np.ndarray:
        return self.image


@pytest.fixture
def pose() -> Iterator[PoseSkeleton]:
    camera = StillCamera(astronaut_bgr())
    sensor = PoseSkeleton("pose", camera, freq=10.0, python=str(mediapipe_python()))
    with camera, sensor:
        yield sensor


def test_the_sensor_gives_her_skeleton_as_a_kinects(pose: PoseSkeleton) -> None:
    assert pose.registers == ("tracked_skeleton",)
    assert eventually(lambda: bool(pose.tracked_skeleton), timeout_s=60)
    (user,) = pose.tracked_skeleton
    assert user == 0
    check_astronaut(pose.tracked_skeleton[0])
    health = pose.health()
    assert health.ok and health.running and health.kind == "PoseSkeleton"
    assert set(pose.read("tracked_skeleton")[0].as_dict()["joints"]) >= {"head", "foot_right"}


def test_a_worker_that_dies_is_lost_then_back(pose: PoseSkeleton) -> None:
    assert eventually(lambda: bool(pose.tracked_skeleton), timeout_s=60)
    worker = pose._worker
    assert worker is not None
    worker._process.kill()
    assert eventually(lambda: pose.health().losses == 1, timeout_s=30)
    assert "pose worker" in pose.health().last_error
    assert eventually(lambda: pose.health().ok and pose._worker is not worker, timeout_s=90)
    pose.remove_all_users()
    assert eventually(lambda: bool(pose.tracked_skeleton), timeout_s=60)


def test_a_config_entry_on_a_video_file(tmp_path: Path) -> None:
    mediapipe_python()  # the entry finds the venv where this does: without it, skip (CI: fail)
    path = tmp_path / "astronaut.avi"
    writer = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"MJPG"), 20.0, (512, 512))
    for _ in range(5):
        writer.write(astronaut_bgr())
    writer.release()
    section = {
        "camera": {"type": "OpenCVCamera", "index": str(path), "fps": 20.0},
        "pose": {"type": "PoseSkeleton", "camera": "camera", "freq": 5.0},
    }
    sensors = build_sensors(checked_sensors(section), opencv_camera)
    try:
        pose = sensors["pose"]
        assert isinstance(pose, PoseSkeleton) and pose.rate_hz == 5.0
        assert pose.camera is sensors["camera"]
        assert eventually(lambda: bool(pose.read("tracked_skeleton")), timeout_s=60)
        check_astronaut(pose.read("tracked_skeleton")[0])
    finally:
        for sensor in reversed(list(sensors.values())):
            sensor.close()


def test_making_the_venv_again_keeps_it() -> None:
    python = mediapipe_python()
    env = dict(os.environ, **command_env({"POPPY_POSE_VENV": str(python.parent.parent)}))
    made = subprocess.run(
        [sys.executable, "-m", "poppy_core.sensors.pose_venv"],
        capture_output=True,
        text=True,
        env=env,
        timeout=120,
        check=False,
    )
    assert made.returncode == 0, made.stderr
    assert made.stdout.strip() == f"pose venv: {python.parent.parent} (mediapipe==0.10.21)"
    assert made.stderr == ""  # nothing installed: the stamp says it holds MediaPipe 0.10.21
