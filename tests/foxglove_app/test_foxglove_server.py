"""`serve --foxglove`: a virtual Ergo Jr seen by a Foxglove WebSocket client (foxglove.sdk.v1):
every channel decodes, joint states are the motors' angles in radians, the URDF and its meshes
come through asset requests, the camera as JPEG images; the token rules hold."""

from __future__ import annotations

import logging
import math
import os
import signal
import subprocess
from collections.abc import Iterator
from pathlib import Path

import pytest
import yaml

pytest.importorskip("foxglove")
pytest.importorskip("mcap_protobuf")

from poppy_core import from_profile
from poppy_core.assembly import Listen, ServerSet, ServeSpec, serve
from poppy_core.errors import ArgumentError
from poppy_core.robot import Robot
from poppy_core.server.errors import ListenError
from tests.foxglove_app.client import FoxgloveClient
from tests.helpers.cli import POPPY, command_env, run_poppy
from tests.helpers.processes import reap
from tests.helpers.waiting import eventually, scaled

ROOT = Path(__file__).resolve().parents[2]
PROFILE = ROOT / "profiles" / "ergo-jr"
URDF = PROFILE / "poppy_ergo_jr.urdf"
TOKEN = "a-token-of-16-chars"


def orientation_signs() -> dict[str, float]:
    """Each motor's sign from the profile (direct +1, indirect -1): its joint's radians are
    ``radians(sign * degrees)`` (the Ergo Jr's offsets are 0)."""
    motors = yaml.safe_load((PROFILE / "profile.yaml").read_text())["motors"]
    return {n: 1.0 if m["orientation"] == "direct" else -1.0 for n, m in motors.items()}


class Served:
    """A virtual Ergo Jr served with ``--foxglove`` on a free loopback port, and a client."""

    def __init__(self, **spec: object) -> None:
        self.robot: Robot = from_profile("ergo-jr", sim=True)
        try:
            self.servers: ServerSet = serve(
                self.robot, ServeSpec(foxglove=Listen("127.0.0.1", 0), name="jr1", **spec)
            )
        except BaseException:
            self.robot.close()
            raise
        assert self.servers.foxglove is not None
        self.client = FoxgloveClient(self.servers.foxglove.url)

    def close(self) -> None:
        self.client.close()
        self.servers.stop()
        self.robot.close()


@pytest.fixture
def served() -> Iterator[Served]:
    robot = Served()
    try:
        yield robot
    finally:
        robot.close()


def test_every_channel_decodes_and_joint_states_are_the_motors_radians(served: Served) -> None:
    robot, client = served.robot, served.client
    robot.sensor("marker_detector").start()  # its detections are published while it runs
    robot.compliant = False
    robot.motor("m1").goal_position = 30.0
    robot.motor("m2").goal_position = -20.0
    assert eventually(lambda: abs(robot.motor("m1").present_position - 30.0) < 0.5, 20.0)
    assert eventually(lambda: abs(robot.motor("m2").present_position + 20.0) < 0.5, 20.0)
    topics = {
        "/joint_states",
        "/tf",
        "/robot_description",
        "/health",
        "/camera/image",
        "/camera/detections",
    }
    assert eventually(lambda: client.topics() == topics, 30.0), client.topics()
    assert eventually(lambda: all(client.of(t) for t in topics), 30.0), {
        t: len(client.of(t)) for t in topics
    }
    schemas = {c["topic"]: c["schemaName"] for c in client.channels.values()}
    assert schemas["/joint_states"] == "foxglove.JointStates"
    assert schemas["/tf"] == "foxglove.FrameTransforms"
    assert schemas["/camera/image"] == "foxglove.CompressedImage"
    assert schemas["/camera/detections"] == "foxglove.ImageAnnotations"
    assert schemas["/health"] == "foxglove.Log"

    signs = orientation_signs()
    count = len(client.of("/joint_states"))
    assert eventually(lambda: len(client.of("/joint_states")) > count + 2, 20.0)
    state = client.of("/joint_states")[-1].decoded
    assert [j.name for j in state.joints] == [m.name for m in robot.motors]
    for joint in state.joints:
        degrees = robot.motor(joint.name).present_position
        assert joint.position == pytest.approx(math.radians(signs[joint.name] * degrees), abs=0.01)
    by_name = {j.name: j.position for j in state.joints}
    assert by_name["m1"] == pytest.approx(math.radians(30.0), abs=0.01)  # direct
    assert by_name["m2"] == pytest.approx(math.radians(20.0), abs=0.01)  # indirect
    assert state.timestamp.seconds > 1_700_000_000  # wall-clock time


def test_tf_is_the_urdf_tree_at_the_motors_angles(served: Served) -> None:
    client = served.client
    assert eventually(lambda: bool(client.of("/tf")), 30.0)
    frames = client.of("/tf")[-1].decoded.transforms
    pairs = {(t.parent_frame_id, t.child_frame_id) for t in frames}
    assert pairs == {
        ("base_link", "long_U"),
        ("long_U", "section_1"),
        ("section_1", "section_2"),
        ("section_2", "section_3"),
        ("section_3", "section_4"),
        ("section_4", "tip"),
    }
    for transform in frames:
        q = transform.rotation
        assert q.x**2 + q.y**2 + q.z**2 + q.w**2 == pytest.approx(1.0, abs=1e-6)


def test_the_urdf_and_its_meshes_come_from_the_server(served: Served) -> None:
    client = served.client
    assert "assets" in client.server_info["capabilities"]
    assert client.server_info["name"] == "poppy jr1"
    assert eventually(lambda: bool(client.of("/robot_description")), 30.0)
    urdf = client.of("/robot_description")[-1].decoded["data"]
    assert urdf == URDF.read_text()
    meshes = sorted({line.split('"')[1] for line in urdf.splitlines() if "package://" in line})
    assert len(meshes) == 7
    for number, uri in enumerate(meshes, start=1):
        client.fetch_asset(uri, number)
    assert eventually(lambda: len(client.assets) == len(meshes), 30.0)
    for number, uri in enumerate(meshes, start=1):
        status, error, data = client.assets[number]
        assert (status, error) == (0, "")
        assert data == (PROFILE / "meshes" / uri.rsplit("/", 1)[1]).read_bytes()
    client.fetch_asset("package://PoppyErgoJr/poppy_ergo_jr.urdf", 100)
    refused = {
        101: "package://PoppyErgoJr/meshes/../profile.yaml",
        102: "package://PoppyErgoJr/profile.yaml",
        103: "package://Other/meshes/tip.STL",
        104: "file:///etc/passwd",
    }
    for number, uri in refused.items():
        client.fetch_asset(uri, number)
    assert eventually(lambda: len(client.assets) == len(meshes) + 5, 30.0)
    assert client.assets[100] == (0, "", URDF.read_bytes())
    for number in refused:
        status, error, data = client.assets[number]
        assert status == 1 and error and data == b""


def test_the_camera_comes_as_jpeg_images(served: Served) -> None:
    client = served.client
    assert eventually(lambda: len(client.of("/camera/image")) >= 2, 30.0)
    image = client.of("/camera/image")[-1].decoded
    assert image.format == "jpeg" and image.frame_id == "camera"
    assert image.data[:2] == b"\xff\xd8" and image.data[-2:] == b"\xff\xd9"
    cv2 = pytest.importorskip("cv2")
    import numpy as np

    picture = cv2.imdecode(np.frombuffer(image.data, dtype=np.uint8), cv2.IMREAD_COLOR)
    assert picture.shape == (480, 640, 3)  # the profile's resolution


def test_health_is_logged_per_bus_and_a_late_client_gets_the_urdf_and_health(
    served: Served,
) -> None:
    assert eventually(lambda: bool(served.client.of("/health")), 30.0)
    lines = [m.decoded for m in served.client.of("/health")]
    assert any(line.message.endswith(": ok") and line.message.startswith("bus ") for line in lines)
    assert {line.name for line in lines} == {"jr1"}
    assert served.servers.foxglove is not None
    late = FoxgloveClient(served.servers.foxglove.url)
    try:
        assert eventually(lambda: bool(late.of("/robot_description")), 30.0)
        assert eventually(lambda: bool(late.of("/health")), 30.0)
    finally:
        late.close()


def test_a_token_keeps_the_foxglove_server_on_loopback() -> None:
    with pytest.raises(ArgumentError, match="no authentication"):
        ServeSpec(foxglove=Listen("0.0.0.0", 0), token=TOKEN)
    on_loopback = Served(token=TOKEN)  # the token's servers' own machine: served
    try:
        assert eventually(lambda: bool(on_loopback.client.of("/joint_states")), 30.0)
    finally:
        on_loopback.close()


def test_a_busy_port_is_a_listen_error(served: Served) -> None:
    assert served.servers.foxglove is not None
    robot = from_profile("ergo-jr", sim=True)
    try:
        with pytest.raises(ListenError, match="already in use"):
            serve(robot, ServeSpec(foxglove=Listen("127.0.0.1", served.servers.foxglove.port)))
    finally:
        robot.close()


def test_poppy_serve_foxglove_says_where_serves_and_stops_on_sigterm() -> None:
    proc = subprocess.Popen(
        [*POPPY, "serve", "--foxglove", "--foxglove-port", "0", "--profile", "ergo-jr", "--sim"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=dict(os.environ, **command_env()),
    )
    try:
        assert proc.stdout is not None and proc.stderr is not None
        line = proc.stdout.readline()
        assert line.startswith("foxglove: ws://127.0.0.1:"), (line, proc.stderr)
        client = FoxgloveClient(line.split()[1])
        try:
            assert eventually(lambda: bool(client.of("/joint_states")), 30.0)
        finally:
            client.close()
        proc.send_signal(signal.SIGTERM)
        assert proc.wait(scaled(30)) == 0
        assert proc.stderr.read().strip().endswith("stopped")
    finally:
        reap(proc)


@pytest.mark.parametrize(
    "args",
    [
        ["--host", "0.0.0.0", "--token", TOKEN],
        ["--http", "--http-port", "8765"],
        ["--snap", "--snap-port", "8765"],
    ],
)
def test_foxglove_refusals_are_one_line_usage_errors(args: list[str]) -> None:
    done = run_poppy("serve", "--foxglove", "--profile", "ergo-jr", "--sim", *args)
    assert done.code == 2, done
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in done.stderr, done.stderr
    assert "foxglove" in lines[0].lower()


def test_a_client_that_leaves_without_closing_is_no_error(
    served: Served, caplog: pytest.LogCaptureFixture
) -> None:
    assert served.servers.foxglove is not None
    caplog.set_level(logging.INFO, logger="foxglove")
    leaving = FoxgloveClient(served.servers.foxglove.url)
    assert eventually(lambda: bool(leaving.of("/joint_states")), 30.0)
    leaving.close()  # drops the connection without a closing handshake
    assert eventually(lambda: any("from client" in r.getMessage() for r in caplog.records), 30.0)
    gone = [r for r in caplog.records if r.getMessage().startswith("Error receiving from client")]
    assert gone and all(r.levelno == logging.INFO for r in gone)
