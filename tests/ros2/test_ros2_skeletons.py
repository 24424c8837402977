"""`poppy serve --ros2` publishes tracked skeletons on /tf: a Kinect's (fed by a fake skeleton
server) and a camera pose's (a stand-in of MediaPipe's worker), a frame per user and joint."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("zenoh")
pytest.importorskip("rosbags")
pytest.importorskip("zmq")

from poppy_core import from_config
from poppy_core.assembly import ServeSpec, serve
from poppy_core.robot import RobotConfig, load_profile
from poppy_core.ros2_wire import Ros2Settings
from poppy_core.zenoh_wire import ZenohSettings
from tests.helpers.pose import fake_pose_python
from tests.helpers.waiting import eventually
from tests.ros2.rmw_client import Collector
from tests.ros2.test_ros2_node import client_session, free_endpoint
from tests.sensors.test_kinect import FakeServer

TF = "tf2_msgs/msg/TFMessage"


def joint_frames(collector: Collector, prefix: str) -> dict[str, Any]:
    """The latest transform of each frame under ``prefix`` received so far."""
    out = {}
    for _, message, _ in collector.snapshot():
        for t in message.transforms:
            if t.child_frame_id.startswith(prefix):
                out[t.child_frame_id] = t
    return out


def test_kinect_and_camera_skeletons_are_tf_frames(tmp_path: Path) -> None:
    server = FakeServer()
    data = load_profile("torso").to_pypot_dict()
    data["sensors"]["kinect"] = {"type": "KinectSensor", "addr": "127.0.0.1", "port": server.port}
    python = str(fake_pose_python(tmp_path))
    data["sensors"]["pose"] = {"type": "PoseSkeleton", "camera": "camera", "python": python}
    endpoint = free_endpoint()
    try:
        with from_config(RobotConfig.from_dict(data), sim=True) as robot:
            settings = Ros2Settings(zenoh=ZenohSettings(listen=(endpoint,)))
            servers = serve(robot, ServeSpec(ros2=settings, name="torso1"))
            session = client_session(endpoint)
            tf = Collector(session, 0, "/tf", TF)
            try:
                assert eventually(lambda: robot.kinect.running, 20.0)  # the node started it

                def kinect_seen() -> bool:
                    server.send(4)
                    return len(joint_frames(tf, "kinect/user_4/")) == 20

                assert eventually(kinect_seen, 30.0)
                assert joint_frames(tf, "pose/") == {}  # a camera pose waits for a reader
                robot.pose.start()
                assert eventually(lambda: len(joint_frames(tf, "pose/user_0/")) == 20, 30.0)
                kinect = joint_frames(tf, "kinect/user_4/")
                pose = joint_frames(tf, "pose/user_0/")
            finally:
                tf.close()
                session.close()
                servers.stop()
    finally:
        server.close()
    elbow = kinect["kinect/user_4/elbow_left"]  # the fake server's joint 5 at (5, 4, 2) m
    assert elbow.header.frame_id == "kinect"
    assert (elbow.transform.translation.x, elbow.transform.translation.y) == (5.0, 4.0)
    assert elbow.transform.translation.z == 2.0 and elbow.transform.rotation.w == 1.0
    elbow = pose["pose/user_0/elbow_left"]  # landmark 13 at (13, 26, 39) cm, Kinect's axes
    assert elbow.header.frame_id == "pose"
    t = elbow.transform.translation
    assert (t.x, t.y, t.z) == pytest.approx((-0.13, -0.26, 0.39))
