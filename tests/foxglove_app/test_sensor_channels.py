"""The sensors of issue 39 in Foxglove: a Kinect's skeletons as a 3D scene, an IMU's orientation
as a transform and its values as JSON, blobs as circles over the camera's image; served to a
Foxglove WebSocket client and recorded to MCAP (every channel decodes)."""

from __future__ import annotations

import io
import json
import math
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("foxglove")
pytest.importorskip("mcap_protobuf")
pytest.importorskip("zmq")
pytest.importorskip("cv2")

import foxglove
from foxglove.messages import SceneEntityDeletionType

from poppy_core import from_config
from poppy_core.assembly import Listen, ServeSpec, serve
from poppy_core.robot import Robot, RobotConfig, load_profile
from poppy_core.sensors.blobs import Blob
from poppy_core.sensors.imu import StillIMU, quaternion_of
from poppy_core.sensors.kinect import JOINTS, parse_skeleton
from poppy_core.server.foxglove import FoxglovePublisher, McapRecording
from poppy_core.server.foxglove.robot_messages import image_annotations
from poppy_core.server.foxglove.sensor_messages import BONES, imu_transform, skeletons_scene
from tests.foxglove_app.client import FoxgloveClient
from tests.foxglove_app.test_detections_and_health import decoded, robot_of
from tests.foxglove_app.test_mcap import read_back
from tests.helpers.waiting import eventually
from tests.sensors.test_kinect import FakeServer, joints_array

SENSOR_TOPICS = {"/kinect/skeletons", "/imu/imu", "/imu/imu/values"}


def robot_with_sensors(kinect_port: int) -> Robot:
    """A virtual Ergo Jr with a Razor IMU (level and still under sim), a Kinect reading the
    fake server and a blob detector keeping the dark pixels of the ideal (black) camera."""
    data = load_profile("ergo-jr").to_pypot_dict()
    data["sensors"]["imu"] = {"type": "RazorIMU", "port": "/dev/ttyACM0"}
    data["sensors"]["kinect"] = {"type": "KinectSensor", "addr": "127.0.0.1", "port": kinect_port}
    data["sensors"]["blob"] = {
        "type": "BlobDetector",
        "cameras": ["camera"],
        "freq": 5.0,
        "filters": {"R": [0, 20], "G": [0, 20], "B": [0, 20]},
    }
    return from_config(RobotConfig.from_dict(data, source="robot.json"), sim=True)


@pytest.fixture
def kinect_server() -> Iterator[FakeServer]:
    made = FakeServer()
    yield made
    made.close()


def sending(server: FakeServer, seen: Any) -> bool:
    """The server sends user 3 until ``seen()`` (a SUB socket misses what came before it)."""

    def sent() -> bool:
        server.send(3)
        return bool(seen())

    return eventually(sent, timeout_s=30, interval_s=0.1)


def check_skeleton(scene: Any) -> None:
    """User 3's skeleton of the fake server (joint i at (i, 3, 2) m): 20 spheres, 19 bones."""
    [entity] = scene.entities
    assert entity.frame_id == "kinect" and entity.id == "user 3"
    centres = [(s.pose.position.x, s.pose.position.y, s.pose.position.z) for s in entity.spheres]
    assert centres == [(float(i), 3.0, 2.0) for i in range(len(JOINTS))]
    [bones] = entity.lines
    assert len(bones.points) == 2 * len(BONES) == 38
    at = {name: float(i) for i, name in enumerate(JOINTS)}
    ends = [p.x for p in bones.points]
    assert ends[:2] == [at["hip_center"], at["spine"]]
    pairs = list(zip(ends[::2], ends[1::2], strict=True))
    assert (at["shoulder_center"], at["shoulder_left"]) in pairs
    assert (at["ankle_right"], at["foot_right"]) == tuple(ends[-2:])


def check_imu(transform: Any, values: dict[str, Any]) -> None:
    """A level, still IMU: the identity rotation, zero angles and rates, gravity on z."""
    assert (transform.parent_frame_id, transform.child_frame_id) == ("world", "imu")
    q = transform.rotation
    assert (q.x, q.y, q.z, q.w) == pytest.approx((0.0, 0.0, 0.0, 1.0))
    assert values["orientation"] == {"yaw": 0.0, "pitch": 0.0, "roll": 0.0}
    assert values["quaternion"] == {"w": 1.0, "x": 0.0, "y": 0.0, "z": 0.0}
    assert values["angular_velocity"] == {"x": 0.0, "y": 0.0, "z": 0.0}
    assert values["acceleration"]["z"] == pytest.approx(9.81, abs=0.01)
    assert values["timestamp"]["sec"] > 1_700_000_000


def check_blob(annotations: Any) -> None:
    """The black frame is one blob: a circle about its centre."""
    [circle] = annotations.circles
    assert 300 <= circle.position.x <= 340 and 220 <= circle.position.y <= 260  # 640×480
    assert circle.diameter > 100
    assert [t.text for t in annotations.texts] == ["blob"]


def test_a_blob_is_a_circle_over_the_image() -> None:
    annotations = decoded(image_annotations([Blob((50, 40), 12, "camera")], 1_800_000_000.0))
    [circle] = annotations.circles
    assert (circle.position.x, circle.position.y, circle.diameter) == (50.0, 40.0, 24.0)
    assert not annotations.points


def test_served_sensors_reach_a_foxglove_client(kinect_server: FakeServer) -> None:
    robot = robot_with_sensors(kinect_server.port)
    try:
        robot.blob.start()  # detections are published while the detector runs
        servers = serve(robot, ServeSpec(foxglove=Listen("127.0.0.1", 0), name="jr1"))
        assert servers.foxglove is not None
        client = FoxgloveClient(servers.foxglove.url)
        try:
            advertised = SENSOR_TOPICS | {"/camera/detections"}
            assert eventually(lambda: client.topics() >= advertised, 30), client.topics()
            schemas = {c["topic"]: c["schemaName"] for c in client.channels.values()}
            assert schemas["/kinect/skeletons"] == "foxglove.SceneUpdate"
            assert schemas["/imu/imu"] == "foxglove.FrameTransform"
            assert schemas["/imu/imu/values"] == "poppy.ImuValues"
            assert sending(kinect_server, lambda: client.of("/kinect/skeletons"))
            assert eventually(lambda: client.of("/imu/imu") and client.of("/imu/imu/values"), 30)
            assert eventually(
                lambda: any(m.decoded.circles for m in client.of("/camera/detections")), 30
            )
            check_skeleton(client.of("/kinect/skeletons")[-1].decoded)
            check_imu(client.of("/imu/imu")[-1].decoded, client.of("/imu/imu/values")[-1].decoded)
            found = [m.decoded for m in client.of("/camera/detections") if m.decoded.circles]
            check_blob(found[-1])
            assert not client.errors
        finally:
            client.close()
            servers.stop()
    finally:
        robot.close()


def test_nothing_is_published_before_a_sensor_has_a_value(kinect_server: FakeServer) -> None:
    """A Kinect whose server sends nothing: its channel is advertised, no scene goes out and
    the joint states flow (the state loop never waits for the first skeleton)."""
    robot = robot_with_sensors(kinect_server.port)
    try:
        servers = serve(robot, ServeSpec(foxglove=Listen("127.0.0.1", 0), name="jr1"))
        assert servers.foxglove is not None
        client = FoxgloveClient(servers.foxglove.url)
        try:
            assert eventually(lambda: "/kinect/skeletons" in client.topics(), 30)
            assert eventually(lambda: len(client.of("/joint_states")) > 20, 30)
            assert eventually(lambda: client.of("/imu/imu"), 30)
            assert robot.kinect.running and robot.kinect.health().age_s is None
            assert client.of("/kinect/skeletons") == []
        finally:
            client.close()
            servers.stop()
    finally:
        robot.close()


def test_a_recording_holds_the_sensor_channels(tmp_path: Path, kinect_server: FakeServer) -> None:
    path = tmp_path / "take.mcap"
    robot = robot_with_sensors(kinect_server.port)
    try:
        robot.blob.start()
        recording = McapRecording(robot, path, "jr1", state_rate_hz=20.0).start()
        try:
            assert set(recording.topics) >= SENSOR_TOPICS | {"/camera/detections"}
            sensors = recording.publisher.sensors
            assert sending(kinect_server, lambda: "kinect" in sensors._last)
            assert eventually(lambda: "imu" in sensors._last, 30)
            detected = recording.publisher._detected
            assert eventually(lambda: detected.get("camera", (0, []))[1] != [], 30)
        finally:
            recording.stop()
    finally:
        robot.close()
    messages = read_back(path)  # every channel decodes
    assert set(messages) >= SENSOR_TOPICS
    check_skeleton(messages["/kinect/skeletons"][-1])
    check_imu(messages["/imu/imu"][-1], messages["/imu/imu/values"][-1])
    check_blob(next(a for a in reversed(messages["/camera/detections"]) if a.circles))
    assert math.isfinite(messages["/imu/imu/values"][-1]["acceleration"]["z"])


def test_a_user_no_longer_tracked_is_deleted_from_the_scene() -> None:
    skeleton = parse_skeleton(
        json.dumps({"shape": [20, 10], "timestamp": 1.0, "user_index": 2}).encode(),
        ",".join(repr(float(v)) for v in joints_array(2).flat).encode(),
    )
    scene = decoded(skeletons_scene({2: skeleton}, [5], "kinect", 1_800_000_000.0))
    assert [e.id for e in scene.entities] == ["user 2"]
    [deletion] = scene.deletions
    assert deletion.id == "user 5" and deletion.type == SceneEntityDeletionType.MatchingId.value


def test_a_turned_imu_turns_its_frame() -> None:
    """Yaw 90° (counter-clockwise about z): the IMU's x axis along the reference's y."""
    transform = decoded(imu_transform(quaternion_of(90.0, 0.0, 0.0), "imu", 1_800_000_000.0))
    q = transform.rotation
    half = math.sqrt(0.5)
    assert (q.x, q.y, q.z, q.w) == pytest.approx((0.0, 0.0, half, half))


class FailedImu(StillIMU):
    """An IMU that read values, then failed for good: its registers raise."""

    def update(self) -> bool | None:
        super().update()
        self.fail("the device is gone for good")
        return None


def test_a_failed_imu_holds_no_joint_state_back() -> None:
    imu = FailedImu("imu", 50.0)
    context = foxglove.Context()
    stream = io.BytesIO()
    publisher = FoxglovePublisher(robot_of(imu), context, "jr1", state_rate_hz=50)
    writer = foxglove.open_mcap(stream, context=context)
    try:
        publisher.start()
        assert eventually(lambda: imu.health().age_s is not None, 30)
        published = publisher.published
        assert eventually(lambda: publisher.published > published + 20, 30)
        assert publisher.state_loop.failures == 0
    finally:
        publisher.close()
        writer.close()
        imu.close()
