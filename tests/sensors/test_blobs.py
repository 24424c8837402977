"""BlobDetector: coloured blobs found by pypot's colour filters, in drawn frames and through a
robot's camera, from a pypot config entry."""

from __future__ import annotations

import re
from typing import Any

import numpy as np
import pytest

from poppy_core import from_config
from poppy_core.errors import ConfigError, SensorError
from poppy_core.robot import RobotConfig, load_profile
from poppy_core.sensors.blobs import Blob, BlobDetector, check_filters, find_blobs
from poppy_core.sensors.camera import DummyCamera
from tests.helpers.sensor_rest import rest
from tests.helpers.waiting import eventually

cv2 = pytest.importorskip("cv2")

RED = {"R": (150, 255), "G": (0, 90), "B": (0, 90)}
BLUE_HSV = {"H": (100, 130), "S": (150, 255), "V": (80, 255)}


def scene() -> np.ndarray:
    """A grey 320×240 frame (BGR) with a red ball, a smaller blue one and a speck of red."""
    image = np.full((240, 320, 3), 128, np.uint8)
    cv2.circle(image, (80, 120), 30, (30, 30, 220), -1)
    cv2.circle(image, (240, 60), 15, (200, 80, 20), -1)
    image[200:202, 300:302] = (30, 30, 220)  # 2×2 pixels: noise, not a blob
    return image


def test_rgb_filters_find_the_red_ball_where_it_is() -> None:
    (ball,) = find_blobs(scene(), check_filters(RED))
    assert abs(ball.center[0] - 80) <= 1 and abs(ball.center[1] - 120) <= 1
    assert abs(ball.radius - 30) <= 2
    assert ball.json == {"center": ball.center, "radius": ball.radius}  # pypot's form


def test_hsv_filters_find_the_blue_ball_and_several_come_largest_first() -> None:
    (blue,) = find_blobs(scene(), check_filters(BLUE_HSV))
    assert abs(blue.center[0] - 240) <= 1 and abs(blue.radius - 15) <= 2
    image = scene()
    cv2.circle(image, (200, 180), 20, (30, 30, 220), -1)
    big, small = find_blobs(image, check_filters(RED))
    assert big.radius > small.radius and abs(small.center[0] - 200) <= 1


def test_draw_circles_the_blob() -> None:
    image = np.zeros((100, 100, 3), np.uint8)
    Blob((50, 50), 20).draw(image, (0, 255, 0), 1)
    assert image[50, 70].tolist() == [0, 255, 0] and image[50, 50].tolist() == [0, 0, 0]


@pytest.mark.parametrize(
    ("filters", "said"),
    [
        ({}, "filters must name at least one of R, G, B, H, S, V"),
        ({"X": [0, 10]}, "unknown filter channel 'X' (R, G, B, H, S or V)"),
        ({"H": [0, 200]}, "filter H must be [min, max] within 0-179"),
        ({"R": [200, 100]}, "filter R must be [min, max] within 0-255"),
        ({"R": [0]}, "filter R must be [min, max] within 0-255"),
        ({"R": [0, float("nan")]}, "filter R must be [min, max] within 0-255"),
    ],
)
def test_bad_filters_are_one_line(filters: dict[str, Any], said: str) -> None:
    with pytest.raises(SensorError, match=rf"^sensor 'blob': {re.escape(said)}$"):
        check_filters(filters, "blob")


class SceneCamera(DummyCamera):
    """A camera that sees ``scene()``."""

    def grab(self) -> np.ndarray:
        return scene()


def test_the_detector_reads_its_camera_in_the_background() -> None:
    camera = SceneCamera("camera", (320, 240), 20.0)
    with camera, BlobDetector("blob", [camera], 10.0, filters=RED) as detector:
        camera.start()
        assert eventually(lambda: len(detector.blobs) == 1)
        assert detector.health().kind == "BlobDetector"


def _config(entry: dict[str, Any]) -> RobotConfig:
    data = load_profile("ergo-jr").to_pypot_dict()
    data["sensors"]["blob"] = entry
    return RobotConfig.from_dict(data, source="robot.json")


def test_a_pypot_config_entry_reads_through_rest() -> None:
    entry = {
        "type": "BlobDetector",
        "cameras": ["camera"],
        "freq": 5.0,
        "filters": {"R": [150, 255]},
    }
    with from_config(_config(entry), sim=True) as robot:
        assert robot.blob.filters == {"R": (150, 255)}
        assert robot.blob.blobs == []  # the ideal robot's camera is black
        with rest(robot) as client:
            value = client.get("/sensors/blob/registers/blobs/value.json").json()
        assert value == {"blobs": []}


@pytest.mark.parametrize(
    ("entry", "said"),
    [
        ({"type": "BlobDetector", "cameras": ["camera"]}, "BlobDetector needs its 'filters' key"),
        (
            {"type": "BlobDetector", "cameras": ["camera"], "filters": {"Q": [0, 1]}},
            "sensors.blob.filters",
        ),
    ],
)
def test_bad_entries_are_refused_at_load(entry: dict[str, Any], said: str) -> None:
    with pytest.raises(ConfigError, match=said) as caught:
        _config(entry)
    assert "\n" not in str(caught.value)
