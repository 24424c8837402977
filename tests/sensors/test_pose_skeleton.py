"""PoseSkeleton without MediaPipe: landmarks to the Kinect's joints, the config, a missing venv."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from poppy_core import from_config
from poppy_core.errors import ConfigError
from poppy_core.robot import RobotConfig, load_profile
from poppy_core.sensors import DummyCamera, PoseSkeleton
from poppy_core.sensors.kinect import JOINTS
from poppy_core.sensors.pose import JOINT_LANDMARKS, skeleton_from_landmarks
from tests.helpers.waiting import within


def landmarks() -> tuple[np.ndarray, np.ndarray]:
    """33 landmarks: landmark i at (i / 40, i / 80) of the image, and at (i, 2i, 3i) cm."""
    index = np.arange(33, dtype=float)
    image = np.stack([index / 40, index / 80, np.zeros(33), np.ones(33)], axis=1)
    world = np.stack([index, 2 * index, 3 * index], axis=1) / 100
    return image, world


def test_the_joints_are_the_kinects_at_their_landmarks() -> None:
    image, world = landmarks()
    skeleton = skeleton_from_landmarks(image, world, (640, 480), timestamp=1.5, user_id=0)
    assert skeleton.joints == JOINTS and skeleton.user_id == 0 and skeleton.timestamp == 1.5
    # a landmark's own joint: the pixel is the landmark times the frame's size
    elbow = skeleton.elbow_left  # MediaPipe's left elbow is landmark 13
    assert elbow.pixel_coordinate == pytest.approx((13 / 40 * 640, 13 / 80 * 480))
    # the Kinect's axes: x to the camera's left (MediaPipe's x right), y up (MediaPipe's down)
    assert elbow.position == pytest.approx((-0.13, -0.26, 0.39))
    # a hand: the middle of the index (19) and little finger (17) knuckles
    assert skeleton.hand_left.pixel_coordinate[0] == pytest.approx(18 / 40 * 640)
    assert skeleton.hip_center.position[0] == pytest.approx(-0.235)  # hips 23 and 24
    for name in JOINTS:
        assert abs(sum(JOINT_LANDMARKS[name].values()) - 1.0) < 1e-9


def test_a_joints_orientation_turns_y_onto_its_bone() -> None:
    image, world = landmarks()
    skeleton = skeleton_from_landmarks(image, world, (640, 480))
    for child, parent in (("elbow_left", "shoulder_left"), ("knee_right", "hip_right")):
        x, y, z, w = getattr(skeleton, child).orientation
        rotation = np.array(
            [
                [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
            ]
        )
        bone = np.subtract(getattr(skeleton, child).position, getattr(skeleton, parent).position)
        assert rotation @ [0.0, 1.0, 0.0] == pytest.approx(bone / np.linalg.norm(bone))


def test_wrong_landmark_counts_are_refused() -> None:
    image, world = landmarks()
    with pytest.raises(ValueError, match="33 landmarks"):
        skeleton_from_landmarks(image[:20], world, (640, 480))


def _config(entry: dict[str, Any]) -> RobotConfig:
    data = load_profile("torso").to_pypot_dict()
    data["sensors"]["pose"] = entry
    return RobotConfig.from_dict(data, source="robot.json")


def test_without_mediapipe_the_robot_builds_and_health_says_why(tmp_path: Any) -> None:
    missing = str(tmp_path / "no-venv" / "bin" / "python")
    config = _config({"type": "PoseSkeleton", "camera": "camera", "python": missing})
    with from_config(config, sim=True) as robot:
        assert isinstance(robot.pose, PoseSkeleton) and robot.pose.camera is robot.camera
        health = robot.sensor_health()["pose"]
        assert not health.ok and "no interpreter" in health.last_error
        assert "mimic" in robot.primitive_names  # a Torso with a skeleton sensor


def test_reading_a_sensor_that_failed_for_good_does_not_revive_it(
    tmp_path: Any, caplog: pytest.LogCaptureFixture
) -> None:
    # Reading started the sensor's thread again, which tried the missing interpreter: health
    # then said "cannot run ...: No such file" in place of why, once the thread was quick enough
    # (a mimic on a busy machine reported either).
    camera = DummyCamera("camera", (64, 48), 10.0)
    sensor = PoseSkeleton("pose", camera, python=str(tmp_path / "no" / "python"))
    with camera, sensor:
        assert sensor.tracked_skeleton == {}
        assert not within(lambda: "cannot run" in sensor.health().last_error, 1.0)
        assert sensor.tracked_skeleton == {}
        health = sensor.health()
        assert not health.ok and "no interpreter" in health.last_error
    assert not [r for r in caplog.records if "cannot run" in r.getMessage()]


@pytest.mark.parametrize(
    ("entry", "said"),
    [
        ({"type": "PoseSkeleton"}, "sensors.pose.camera.*must name the camera sensor"),
        ({"type": "PoseSkeleton", "camera": "pose"}, "sensors.pose.camera.*is not a camera"),
        ({"type": "PoseSkeleton", "cameras": ["camera", "camera"]}, "must name the camera"),
        ({"type": "PoseSkeleton", "camera": "camera", "python": ""}, "sensors.pose.python"),
    ],
)
def test_bad_entries_are_one_line(entry: dict[str, Any], said: str) -> None:
    with pytest.raises(ConfigError, match=said) as caught:
        _config(entry)
    assert "\n" not in str(caught.value)


def test_a_cameras_list_of_one_works_too() -> None:
    config = _config({"type": "PoseSkeleton", "cameras": ["camera"], "python": "/nonexistent"})
    assert config.sensors["pose"].spec("pose").cameras == ("camera",)
