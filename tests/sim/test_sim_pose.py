"""In MuJoCo, a Torso's simulated camera sees the astronaut's picture: a PoseSkeleton from the
config gives her skeleton (robot, REST), and ``mimic`` moves the arms to her arms' directions,
checked through the chains' forward kinematics."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest

pytest.importorskip("mujoco")
pytest.importorskip("cv2")

from sim_helpers import ahead_of_camera, ready_to_look

from poppy_core.creatures.arm_directions import person_arms, robot_arm_for
from tests.helpers.arms import angle_deg, robot_arms
from tests.helpers.pose import mediapipe_python
from tests.helpers.sensor_rest import rest
from tests.helpers.waiting import eventually

skimage_data = pytest.importorskip("skimage.data")

pytestmark = [pytest.mark.slow, pytest.mark.gl]  # renders with OpenGL in the test process


@pytest.fixture(scope="module")
def torso() -> Iterator[Any]:
    from poppy_core import from_config
    from poppy_core.robot import RobotConfig, load_profile

    python = str(mediapipe_python())
    data = load_profile("torso").to_dict()
    data["sensors"]["pose"] = {"type": "PoseSkeleton", "camera": "camera", "python": python}
    config = RobotConfig.from_dict(data, source="test")
    with from_config(config, sim="mujoco", start_defaults=False) as robot:
        yield ready_to_look(robot)


def test_the_simulated_camera_sees_her_and_the_arms_follow(torso: Any) -> None:
    sim = torso.simulation
    torso.pose.start()
    picture = skimage_data.astronaut()
    sim.add_picture("astronaut", picture, ahead_of_camera(sim, 0.45, 0.0), size=0.8)
    assert eventually(lambda: bool(torso.pose.tracked_skeleton), timeout_s=90)
    skeleton = torso.pose.tracked_skeleton[0]
    head, left, right = (
        getattr(skeleton, n).pixel_coordinate for n in ("head", "shoulder_left", "shoulder_right")
    )
    assert right.x < head.x < left.x  # facing the robot: her left on the frame's right
    assert head.y < min(left.y, right.y)
    with rest(torso) as client:
        value = client.get("/sensors/pose/registers/tracked_skeleton/value.json").json()
    assert set(value["tracked_skeleton"]["0"]["joints"]) >= {"hip_center", "foot_right"}

    # arms held out first, so that following her (arms down) is a move
    torso.goto_position({"l_shoulder_x": 70.0, "r_shoulder_x": -70.0}, 1.0, wait=True)
    mimic = torso.mimic
    assert mimic.source is torso.pose and mimic.mirror
    mimic.smoothing = 0.0

    def wanted() -> dict[str, Any]:
        arms = person_arms(torso.pose.tracked_skeleton.get(0, skeleton))
        return {side: robot_arm_for(arms, side, mirror=True) for side in ("left", "right")}

    def error_deg() -> float:
        now, want = robot_arms(torso), wanted()
        return max(angle_deg(now[s][i], want[s][i]) for s in now for i in (0, 1))

    assert error_deg() > 30.0
    mimic.start()
    try:
        assert eventually(lambda: error_deg() < 15.0, timeout_s=60), error_deg()
    finally:
        mimic.stop()
    assert mimic.error is None
