"""`poppy serve --ros2`: the other topics (tf, tf_static, diagnostics, camera), the fleet node
beside the ROS 2 node on one session, and rmw_zenoh's wire rules as poppy writes them."""

from __future__ import annotations

import math

import numpy as np
import pytest

pytest.importorskip("zenoh")
pytest.importorskip("rosbags")

from poppy_core import from_profile
from poppy_core import ros2_wire as wire
from poppy_core.assembly import ServeSpec, serve
from poppy_core.errors import ConfigError
from poppy_core.ros2_wire import Ros2Settings
from poppy_core.zenoh_wire import ZenohSettings
from tests.helpers.waiting import eventually
from tests.ros2.rmw_client import Collector
from tests.ros2.test_ros2_node import Node, client_session, free_endpoint

TF = "tf2_msgs/msg/TFMessage"
DIAGNOSTICS = "diagnostic_msgs/msg/DiagnosticArray"
IMAGE = "sensor_msgs/msg/CompressedImage"


def _hashed(name: str) -> str:
    from rosbags.typesys import Stores, get_typestore

    return get_typestore(Stores.ROS2_JAZZY).hash_rihs01(name)


def test_tf_turns_a_joint_with_its_motor(node: Node) -> None:
    node.robot.compliant = False
    node.robot.motor("m1").goal_position = 30.0
    tf = Collector(node.session, 0, "/tf", TF)
    assert tf.key.endswith(_hashed(TF))  # the hash ros2 interface prints, by rosbags

    def m1_turned() -> bool:
        samples = tf.snapshot()
        if not samples:
            return False
        by_child = {t.child_frame_id: t for t in samples[-1][1].transforms}
        joint = next(t for t in by_child.values() if t.header.frame_id == "base_link")
        q = joint.transform.rotation
        angle = 2 * math.atan2(math.sqrt(q.x**2 + q.y**2 + q.z**2), q.w)
        return abs(angle - math.radians(30)) < 0.03

    try:
        assert eventually(m1_turned, 20.0)
        transforms = tf.snapshot()[-1][1].transforms
        assert len(transforms) == 6  # the Ergo Jr's six moving joints
        assert transforms[0].header.stamp.sec > 0
    finally:
        tf.close()


def test_tf_static_and_diagnostics(node: Node) -> None:
    static = node.client.latched("/tf_static", TF)
    assert eventually(lambda: bool(static), 10.0)
    assert static[0].transforms is not None  # the Ergo Jr's URDF has no fixed joint: empty
    diagnostics = Collector(node.session, 0, "/diagnostics", DIAGNOSTICS)
    try:
        assert eventually(lambda: bool(diagnostics.snapshot()), 20.0)
        statuses = diagnostics.snapshot()[0][1].status
    finally:
        diagnostics.close()
    names = [s.name for s in statuses]
    assert any(n.startswith("jr1: bus ") for n in names)
    bus = next(s for s in statuses if s.name.startswith("jr1: bus "))
    assert bus.level == 0 and bus.message == "ok"
    assert {"connected", "offline"} <= {kv.key for kv in bus.values}


def test_the_camera_is_published_while_it_is_open(node: Node) -> None:
    frames = Collector(node.session, 0, "/camera/image_raw/compressed", IMAGE)
    camera = node.robot.sensor("camera")
    try:
        camera.start()  # opened by someone (the page, a primitive): then it is published
        assert eventually(lambda: len(frames.snapshot()) >= 2, 20.0)
        image = frames.snapshot()[-1][1]
        assert image.format == "jpeg"
        assert bytes(np.asarray(image.data)[:2]) == b"\xff\xd8"  # a JPEG's start
        assert image.header.frame_id == "camera"
    finally:
        frames.close()


def test_the_fleet_node_and_the_ros2_node_share_one_session() -> None:
    endpoint = free_endpoint()
    robot = from_profile("ergo-jr", sim=True)
    spec = ServeSpec(
        zenoh=ZenohSettings(listen=(endpoint,)),
        ros2=Ros2Settings(),  # its own settings unused: the fleet's session serves both
        name="both",
    )
    servers = serve(robot, spec)
    try:
        assert servers.zenoh is not None and servers.ros2 is not None
        assert servers.zenoh.session is servers.ros2.session
        session = client_session(endpoint)
        try:
            tokens = [  # `**` matches no `@` chunk: the admin space is asked for apart
                str(r.ok.key_expr)
                for keys in ("poppy/*", "@ros2_lv/**")
                for r in session.liveliness().get(keys)
                if r.ok
            ]
            assert "poppy/both" in tokens
            assert any(t.endswith("/NN/%/%/both") for t in tokens)
        finally:
            session.close()
    finally:
        servers.stop()
        robot.close()


def test_wire_rules() -> None:
    assert wire.DEFAULT_QOS.keyexpr() == "::,10:,:,:,,"
    assert wire.LATCHED_QOS.keyexpr() == ":1:,1:,:,:,,"
    assert wire.SENSOR_QOS.keyexpr() == "2::,5:,:,:,,"
    assert wire.Qos().keyexpr() == "::,:,:,:,,"  # rmw_zenoh's defaults: every part empty
    assert wire.fully_qualified("/", "jr1", "~/set_compliant") == "/jr1/set_compliant"
    assert wire.fully_qualified("/lab", "jr1", "joint_states") == "/lab/joint_states"
    assert wire.fully_qualified("/lab", "jr1", "/tf") == "/tf"
    assert wire.check_namespace("lab/a/") == "/lab/a"
    assert wire.node_name_from("jr-1.local") == "jr_1_local"
    assert wire.node_name_from("7up") == "poppy_7up"
    stamp = 1_700_000_000_123_456_789
    data = wire.attachment(5, stamp, bytes(range(16)))
    assert len(data) == 33 and data[16] == 16  # zenoh-ext: the GID's length, then its bytes
    assert wire.read_attachment(data) == wire.Attachment(5, stamp, bytes(range(16)))
    for bad in (-1, 233, True):
        with pytest.raises(ConfigError, match="domain"):
            wire.check_domain(bad)  # type: ignore[arg-type]
    with pytest.raises(ConfigError, match="namespace"):
        wire.check_namespace("/a b")
    with pytest.raises(ConfigError, match="attachment"):
        wire.read_attachment(b"\x00" * 5)


def test_the_node_leaves_the_graph_when_served_no_more() -> None:
    served = Node()
    try:
        assert eventually(lambda: any("/NN/" in t for t in served.client.tokens()), 10.0)
        served.servers.stop()
        assert eventually(lambda: served.client.tokens() == [], 10.0)
    finally:
        served.close()
