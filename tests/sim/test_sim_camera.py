"""The simulated Ergo Jr's camera: the MuJoCo scene from its head; objects and markers in view."""

from __future__ import annotations

import time
from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest

from poppy_core.errors import SensorError

pytest.importorskip("mujoco")
pytest.importorskip("cv2")


@pytest.fixture(scope="module")
def robot() -> Iterator[Any]:
    from poppy_core import from_profile

    with from_profile("ergo-jr", sim="mujoco") as robot:
        try:
            robot.camera.latest(timeout_s=30)
        except SensorError as exc:
            pytest.skip(f"no OpenGL for offscreen rendering here ({exc}); `make sim-deps`")
        robot.compliant = False  # the zero pose: the head looks ahead, over the table
        robot.goto_position({m.name: 0.0 for m in robot.motors}, 0.5, wait=True)
        time.sleep(0.5)
        yield robot


def fresh(camera: Any) -> np.ndarray:
    """A frame rendered after now (two later, so the scene change is in it)."""
    first = camera.next_frame(-1, timeout_s=30)
    return np.asarray(camera.next_frame(first.number, timeout_s=30).image)


def ahead(robot: Any, distance_m: float) -> tuple[float, float, float]:
    """The point ``distance_m`` in front of the robot's camera, in the world."""
    import mujoco

    sim = robot.simulation
    with sim.lock:
        camera = mujoco.mj_name2id(sim.model, mujoco.mjtObj.mjOBJ_CAMERA, "camera")
        look = -np.asarray(sim.data.cam_xmat[camera]).reshape(3, 3)[:, 2]
        x, y, z = np.asarray(sim.data.cam_xpos[camera]) + distance_m * look
    return (float(x), float(y), float(z))


def test_the_camera_is_the_sim_camera(robot: Any) -> None:
    camera = robot.camera
    assert type(camera).__name__ == "SimCamera" and camera.index == "camera"
    frame = camera.frame
    assert frame.shape == (480, 640, 3) and frame.dtype == np.uint8
    assert camera.calibration is not None
    assert camera.health().ok and camera.health().kind == "SimCamera"


def test_an_object_in_front_changes_the_frame_and_its_marker_is_detected(robot: Any) -> None:
    camera = robot.camera
    before = fresh(camera).astype(int)
    target = ahead(robot, 0.25)
    robot.simulation.add_marker("card", 7, target, size=0.05)
    after = fresh(camera).astype(int)
    centre = (slice(180, 300), slice(260, 380))
    assert np.abs(after[centre] - before[centre]).mean() > 30  # the card fills the centre
    markers = robot.marker_detector.detect()
    assert [(m.id, m.family) for m in markers] == [(7, "aruco")]
    (marker,) = markers
    assert abs(marker.position[0]) < 0.1 and abs(marker.position[1]) < 0.1
    assert marker.pose is not None
    assert marker.pose.distance_m == pytest.approx(0.25, rel=0.05)


def test_a_poppy_card_is_seen_by_name(robot: Any) -> None:
    x, y, z = ahead(robot, 0.3)
    robot.simulation.add_marker("caribou", 221052793, (x + 0.08, y, z), size=0.05, family="hamming")
    fresh(robot.camera)
    deadline = time.monotonic() + 20
    while not robot.marker_detector.sees("caribou") and time.monotonic() < deadline:
        time.sleep(0.1)
    assert robot.marker_detector.sees("caribou")
    assert "caribou" in robot.marker_detector.cards
    assert not robot.marker_detector.sees("tetris")


def test_an_added_object_appears(robot: Any) -> None:
    before = fresh(robot.camera).astype(int)
    x, y, z = ahead(robot, 0.2)
    robot.simulation.add_object("sphere", "ball", (x, y, z + 0.2), size=0.03)
    time.sleep(0.1)
    after = fresh(robot.camera).astype(int)
    assert np.abs(after - before).sum() > 0
