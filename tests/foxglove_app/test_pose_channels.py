"""A camera's PoseSkeleton goes where a Kinect's skeletons go: a Foxglove scene on
``/<name>/skeletons``, REST's register value; fed by a stand-in of MediaPipe's worker (the same
person in every frame), so no MediaPipe is needed."""

from __future__ import annotations

from pathlib import Path

import pytest

pytest.importorskip("foxglove")
pytest.importorskip("mcap_protobuf")

from poppy_core import from_config
from poppy_core.assembly import Listen, ServeSpec, serve
from poppy_core.robot import RobotConfig, load_profile
from poppy_core.sensors import PoseSkeleton, skeleton_sensors
from poppy_core.sensors.kinect import JOINTS
from tests.foxglove_app.client import FoxgloveClient
from tests.helpers.pose import fake_pose_python
from tests.helpers.sensor_rest import rest
from tests.helpers.waiting import eventually


def test_a_pose_skeleton_is_a_scene_and_a_rest_value(tmp_path: Path) -> None:
    data = load_profile("torso").to_pypot_dict()
    python = str(fake_pose_python(tmp_path))
    data["sensors"]["pose"] = {"type": "PoseSkeleton", "camera": "camera", "python": python}
    robot = from_config(RobotConfig.from_dict(data, source="robot.json"), sim=True)
    try:
        assert isinstance(robot.pose, PoseSkeleton)
        assert skeleton_sensors(robot.sensors) == [robot.pose]
        servers = serve(robot, ServeSpec(foxglove=Listen("127.0.0.1", 0), name="torso1"))
        assert servers.foxglove is not None
        client = FoxgloveClient(servers.foxglove.url)
        try:
            assert eventually(lambda: "/pose/skeletons" in client.topics(), 30), client.topics()
            assert eventually(lambda: client.of("/pose/skeletons"), 30)
            [entity] = client.of("/pose/skeletons")[-1].decoded.entities
            assert entity.frame_id == "pose" and entity.id == "user 0"
            assert len(entity.spheres) == len(JOINTS)
            elbow = entity.spheres[JOINTS.index("elbow_left")].pose.position
            # landmark 13 at (13, 26, 39) cm in MediaPipe's axes: x and y turned for the Kinect's
            assert (elbow.x, elbow.y, elbow.z) == pytest.approx((-0.13, -0.26, 0.39))
            assert not client.errors
        finally:
            client.close()
            servers.stop()
        with rest(robot) as http:
            value = http.get("/sensors/pose/registers/tracked_skeleton/value.json").json()
        skeleton = value["tracked_skeleton"]["0"]
        assert set(skeleton["joints"]) == set(JOINTS) and skeleton["user_id"] == 0
        assert skeleton["joints"]["elbow_left"]["pixel_coordinate"] == pytest.approx(
            [13 / 40 * 640, 13 / 80 * 480]
        )
        assert robot.sensor_health()["pose"].ok
    finally:
        robot.close()
