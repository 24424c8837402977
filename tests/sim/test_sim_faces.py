"""In MuJoCo, a face picture in the scene is found through the Ergo Jr's simulated camera, and
face_tracking turns the head until it is in the middle of the view."""

from __future__ import annotations

import time
from collections.abc import Iterator
from typing import Any

import pytest

pytest.importorskip("mujoco")
pytest.importorskip("cv2")

from sim_helpers import ahead_of_camera, ready_to_look

skimage_data = pytest.importorskip("skimage.data")

pytestmark = [pytest.mark.slow, pytest.mark.gl]  # renders with OpenGL in the test process


@pytest.fixture(scope="module")
def ergo() -> Iterator[Any]:
    from poppy_core import from_config
    from poppy_core.robot import RobotConfig, load_profile

    data = load_profile("ergo-jr").to_dict()
    data["sensors"]["face_detector"] = {"type": "FaceDetector", "cameras": ["camera"]}
    with from_config(RobotConfig.from_dict(data, source="test"), sim="mujoco") as robot:
        yield ready_to_look(robot)


def faces_now(robot: Any) -> list[Any]:
    """The faces in a frame rendered from now on (the scene change is in it)."""
    camera = robot.camera
    first = camera.next_frame(-1, timeout_s=30)
    frame = camera.next_frame(first.number, timeout_s=30)
    return list(robot.face_detector.finder.find(frame.image, "camera"))


def test_a_face_in_the_scene_is_found_then_followed_to_the_middle(ergo: Any) -> None:
    sim = ergo.simulation
    assert faces_now(ergo) == []  # the empty scene: no face
    picture = skimage_data.astronaut()[0:256, 100:356]  # her head and shoulders
    sim.add_picture("astronaut", picture, ahead_of_camera(sim, 0.3, 0.06), size=0.14)
    (face,) = faces_now(ergo)
    assert face.position[0] > 0.2 and abs(face.position[1]) < 0.3, face  # right of the middle
    assert 80 <= face.size <= 170
    assert "face_tracking" in ergo.primitive_names
    ergo.face_tracking.start()
    try:
        deadline = time.monotonic() + 60
        now = faces_now(ergo)
        while time.monotonic() < deadline and (not now or max(map(abs, now[0].position)) > 0.12):
            time.sleep(0.2)
            now = faces_now(ergo)
    finally:
        ergo.face_tracking.stop()
    assert now and max(map(abs, now[0].position)) <= 0.12, (face, now)
    assert ergo.m1.present_position < -2.0 or ergo.m1.present_position > 2.0  # the base turned
    assert ergo.face_tracking.error is None
