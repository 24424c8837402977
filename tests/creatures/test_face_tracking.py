"""Ergo Jr's face_tracking, closed through the kinematics: the camera sees a face at a fixed point;
attached to an Ergo Jr whose config has a face detector."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from poppy_core import from_config, from_profile
from poppy_core.creatures import FaceTracking
from poppy_core.robot import RobotConfig, load_profile
from poppy_core.sensors import Face, FaceDetector
from tests.creatures.test_tracking import HEIGHT, WIDTH, SeenPoint, turns_to_centre
from tests.helpers.fixtures import ergo_fixture
from tests.helpers.waiting import eventually

pytest.importorskip("skimage")


class SeenFaces(SeenPoint):
    """A face detector whose face sits at ``point`` of the chain's base frame."""

    def detect(self, camera: Any = None) -> list[Face]:
        seen = self.pixel()
        return [] if seen is None else [face_at(*seen, 60)]


def face_at(u: float, v: float, size: int) -> Face:
    rect = (round(u - size / 2), round(v - size / 2), size, size)
    return Face(rect, (u, v), (2 * u / WIDTH - 1, 2 * v / HEIGHT - 1), "camera", 10)


ergo = ergo_fixture(sensors=False, home=True)


def to_the_side(robot: Any) -> tuple[float, float, float]:
    pose = robot.chain.model.forward({m.name: 0.0 for m in robot.chain.motors})
    look = pose[:3, :3] @ np.array([0.0, 0.0, -1.0])
    side = np.cross(look, [0.0, 0.0, 1.0])
    point = pose[:3, 3] + 0.4 * look + 0.1 * side / np.linalg.norm(side) + np.array([0, 0, -0.04])
    return (float(point[0]), float(point[1]), float(point[2]))


def test_the_head_turns_until_the_face_is_in_the_middle(ergo: Any) -> None:
    detector = SeenFaces(ergo, to_the_side(ergo))
    turns_to_centre(ergo, FaceTracking(ergo, detector=detector, freq=10.0), detector)


def test_the_face_followed_is_kept_when_another_comes(ergo: Any) -> None:
    tracking = FaceTracking(ergo, detector=SeenFaces(ergo, (0.0, 0.0, 0.0)))
    first = face_at(300.0, 250.0, 60)
    assert tracking.pick([first]) is first
    bigger, moved = face_at(60.0, 60.0, 140), face_at(310.0, 245.0, 62)
    assert tracking.pick([bigger, moved]) is moved  # the nearest to the one followed
    assert tracking.pick([]) is None
    tracking.setup()  # started again: the surest first
    assert tracking.pick([bigger, moved]) is bigger


def test_no_face_no_move(ergo: Any) -> None:
    detector = SeenFaces(ergo, (0.0, 0.0, -5.0))  # behind: never in view
    tracking = FaceTracking(ergo, detector=detector, freq=20.0)
    detector.follow = tracking
    goals = {m.name: m.goal_position for m in ergo.motors}
    tracking.start()
    assert eventually(lambda: tracking.running)
    tracking.stop()
    assert {m.name: m.goal_position for m in ergo.motors} == goals


def test_an_ergo_jr_with_a_face_detector_gets_face_tracking() -> None:
    data = load_profile("ergo-jr").to_dict()
    data["sensors"]["camera"] = {"type": "DummyCamera", "resolution": [64, 48]}
    data["sensors"]["face_detector"] = {"type": "FaceDetector", "cameras": ["camera"]}
    with from_config(RobotConfig.from_dict(data), sim=True) as robot:
        assert isinstance(robot.face_detector, FaceDetector)
        tracking = robot.face_tracking
        assert isinstance(tracking, FaceTracking) and tracking.detector is robot.face_detector
        assert robot.face_detector.faces == []  # black frames
    with from_profile("ergo-jr", sim=True) as robot:  # the profile has no face detector
        assert "face_tracking" not in robot.primitive_names
