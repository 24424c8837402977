"""Ergo Jr's marker behaviours, closed through the kinematics: the camera sees a fixed point."""

from __future__ import annotations

import math
import time
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest

from poppy_core.creatures import MarkerFollow, TrackingFeedback
from poppy_core.errors import SensorError
from poppy_core.sensors.camera import CameraCalibration
from poppy_core.sensors.markers import Marker
from tests.helpers.fixtures import ergo_fixture
from tests.helpers.waiting import eventually

WIDTH, HEIGHT = 640, 480


class FakeCamera:
    name = "camera"
    resolution = (WIDTH, HEIGHT)
    calibration = CameraCalibration.from_fov(WIDTH, HEIGHT, 41.4)

    def clock_s(self) -> float:
        return time.monotonic()

    def latest(self) -> Any:
        return SimpleNamespace(time_s=time.monotonic())


class SeenPoint:
    """A marker detector whose marker sits at ``point`` of the chain's base frame: where it
    appears follows from the motors' present positions, as a camera at the tip would see it."""

    def __init__(self, robot: Any, point: tuple[float, float, float], marker_id: int = 7) -> None:
        self.robot = robot
        self.point = np.asarray(point)
        self.marker_id = marker_id
        self.cameras = [FakeCamera()]
        self.card_ids = {"caribou": [221052793]}
        self.hidden = False
        self.follow: MarkerFollow | None = None

    def pixel(self) -> tuple[float, float] | None:
        chain = self.robot.chain
        pose = chain.model.forward({m.name: m.present_position for m in chain.motors})
        assert self.follow is not None
        right, down, look = (pose[:3, :3] @ axis for axis in self.follow.camera_axes())
        towards = self.point - pose[:3, 3]
        depth = float(towards @ look)
        if depth <= 0:
            return None
        matrix = FakeCamera.calibration.camera_matrix
        u = matrix[0, 2] + matrix[0, 0] * float(towards @ right) / depth
        v = matrix[1, 2] + matrix[1, 1] * float(towards @ down) / depth
        return (u, v) if 0 <= u < WIDTH and 0 <= v < HEIGHT else None

    @property
    def markers(self) -> list[Marker]:
        seen = None if self.hidden else self.pixel()
        if seen is None:
            return []
        u, v = seen
        corners = ((u - 10, v - 10), (u + 10, v - 10), (u + 10, v + 10), (u - 10, v + 10))
        position = (2 * u / WIDTH - 1, 2 * v / HEIGHT - 1)
        return [Marker(self.marker_id, "aruco", corners, (u, v), position, "camera")]

    def detect(self, camera: Any = None) -> list[Marker]:
        return self.markers


ergo = ergo_fixture(sensors=False, stiff=True)


def off_centre_px(detector: SeenPoint) -> float:
    seen = detector.pixel()
    return math.inf if seen is None else math.hypot(seen[0] - WIDTH / 2, seen[1] - HEIGHT / 2)


def test_the_head_turns_until_the_marker_is_in_the_middle(ergo: Any) -> None:
    ergo.goto_position({m.name: 0.0 for m in ergo.motors}, 0.3, wait=True)
    pose = ergo.chain.model.forward({m.name: 0.0 for m in ergo.chain.motors})
    tip = pose[:3, 3]
    look = pose[:3, :3] @ np.array([0.0, 0.0, -1.0])
    side = np.cross(look, [0.0, 0.0, 1.0])
    point = tip + 0.3 * look + 0.08 * side / np.linalg.norm(side) + np.array([0.0, 0.0, 0.03])
    detector = SeenPoint(ergo, tuple(point))
    turns_to_centre(ergo, MarkerFollow(ergo, detector=detector, freq=10.0), detector)


def turns_to_centre(ergo: Any, follow: Any, detector: SeenPoint) -> None:
    """Run ``follow`` until what ``detector`` sees is in the middle of the image: it must start
    well off the middle, and the base must have turned towards it."""
    detector.follow = follow
    before = off_centre_px(detector)
    assert 60 < before < 300, before  # in view, well off the middle
    follow.start()
    try:
        assert eventually(lambda: off_centre_px(detector) < 40, 20.0), off_centre_px(detector)
    finally:
        follow.stop()
    assert abs(ergo.m1.present_position) > 3.0  # the base turned towards the side
    assert follow.error is None


def test_a_marker_out_of_the_list_is_not_followed(ergo: Any) -> None:
    pose = ergo.chain.model.forward({m.name: m.present_position for m in ergo.chain.motors})
    point = pose[:3, 3] + 0.3 * (pose[:3, :3] @ np.array([0.05, 0.05, -1.0]))
    detector = SeenPoint(ergo, tuple(point), marker_id=7)
    follow = MarkerFollow(ergo, detector=detector, marker="caribou", freq=10.0)
    detector.follow = follow
    goals = {m.name: m.goal_position for m in ergo.motors}
    follow.start()
    time.sleep(0.6)
    follow.stop()
    assert {m.name: m.goal_position for m in ergo.motors} == goals
    with pytest.raises(SensorError, match="no card 'zebra'"):
        follow.marker = "zebra"
    follow.marker = 7
    assert follow.marker == 7


def test_the_leds_say_whether_a_marker_is_seen(ergo: Any) -> None:
    detector = SeenPoint(ergo, (0.0, 0.0, 0.0))
    detector.follow = MarkerFollow(ergo, detector=detector)
    ahead = ergo.chain.model.forward({m.name: m.present_position for m in ergo.chain.motors})
    detector.point = ahead[:3, 3] + 0.3 * (ahead[:3, :3] @ np.array([0.0, 0.0, -1.0]))
    feedback = TrackingFeedback(ergo, freq=20.0, detector=detector)
    feedback.start()
    try:
        assert eventually(lambda: all(ergo.motor(n).led == "green" for n in ("m4", "m5", "m6")), 5)
        assert ergo.m1.led == "off"
        detector.hidden = True
        assert eventually(lambda: all(ergo.motor(n).led == "off" for n in ("m4", "m5", "m6")), 5)
    finally:
        feedback.stop()
