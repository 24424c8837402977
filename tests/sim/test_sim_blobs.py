"""In MuJoCo, a red ball held in front of the Ergo Jr's simulated camera is a blob where it is."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest
from sim_helpers import ahead_of_camera, ready_to_look

pytest.importorskip("mujoco")
cv2 = pytest.importorskip("cv2")

pytestmark = [pytest.mark.slow, pytest.mark.gl]  # renders with OpenGL in the test process

RED = {"H": [0, 10], "S": [120, 255], "V": [60, 255]}  # lit by the scene: a darker red


@pytest.fixture(scope="module")
def ergo() -> Iterator[Any]:
    from poppy_core import from_config
    from poppy_core.robot import RobotConfig, load_profile

    data = load_profile("ergo-jr").to_dict()
    data["sensors"]["ball"] = {"type": "BlobDetector", "cameras": ["camera"], "filters": RED}
    with from_config(RobotConfig.from_dict(data, source="test"), sim="mujoco") as robot:
        yield ready_to_look(robot)


def blobs_now(robot: Any, changed: bool = False) -> list[Any]:
    """The blobs in a frame rendered from now on; ``changed``: in the first of the next ten
    frames that shows any (a frame being rendered when the scene changed may not show it yet,
    and a busy machine renders several before the change is in)."""
    camera = robot.camera
    frame = camera.next_frame(-1, timeout_s=30)
    for _ in range(10):
        frame = camera.next_frame(frame.number, timeout_s=30)
        found: list[Any] = robot.ball.find(frame.image, camera)
        if found or not changed:
            return found
    return found


def test_a_red_ball_right_of_the_view_is_one_blob_right_of_the_middle(ergo: Any) -> None:
    assert blobs_now(ergo) == []  # the scene has nothing red
    ball = np.full((64, 64, 3), 255, np.uint8)  # RGB: a red disc on white, seen head on
    cv2.circle(ball, (32, 32), 30, (220, 30, 30), -1)
    ergo.simulation.add_picture("ball", ball, ahead_of_camera(ergo.simulation, 0.3, 0.05), 0.06)
    (blob,) = blobs_now(ergo, changed=True)
    width = ergo.camera.resolution[0]
    assert blob.center[0] > width / 2 + 10, blob  # right of the middle, as placed
    assert 5 <= blob.radius <= width / 4, blob
    assert ergo.ball.blobs and ergo.ball.blobs[0].camera == "camera"
