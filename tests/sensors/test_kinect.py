"""KinectSensor: the skeletons the Kinect skeleton server publishes, from a fake server that
sends on ZMQ what the Windows server sends (a JSON header, then the comma-separated joints)."""

from __future__ import annotations

import json
import logging
import socket
from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest

from poppy_core import from_config
from poppy_core.errors import ConfigError
from poppy_core.robot import RobotConfig, load_profile
from poppy_core.sensors.kinect import JOINTS, KinectSensor, Skeleton, parse_skeleton
from tests.helpers.sensor_rest import rest
from tests.helpers.waiting import eventually

zmq = pytest.importorskip("zmq")


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


def joints_array(user: int) -> np.ndarray:
    """20 joints × (x, y, z, w, px, py, qx, qy, qz, qw): joint i at (i, user, 2) m, w = 2."""
    rows = [[2.0 * i, 2.0 * user, 4.0, 2.0, 10.0 * i, 5.0, 0.0, 0.0, 0.0, 1.0] for i in range(20)]
    return np.array(rows)


class FakeServer:
    """The skeleton server's side: a PUB socket on loopback."""

    def __init__(self) -> None:
        self.port = free_port()
        self.socket = zmq.Context.instance().socket(zmq.PUB)
        self.socket.setsockopt(zmq.LINGER, 0)
        self.socket.bind(f"tcp://127.0.0.1:{self.port}")

    def send(self, user: int, timestamp: float = 1.5, array: Any = None) -> None:
        values = joints_array(user) if array is None else array
        header = {"shape": list(values.shape), "timestamp": timestamp, "user_index": user}
        self.socket.send_json(header)
        self.socket.send(",".join(repr(float(v)) for v in values.flat).encode())

    def close(self) -> None:
        self.socket.close()


@pytest.fixture
def server() -> Iterator[FakeServer]:
    made = FakeServer()
    yield made
    made.close()


def sent_until_seen(server: FakeServer, kinect: KinectSensor, user: int) -> bool:
    """The server sends until the sensor has the user (a SUB socket misses what was sent before
    it joined, as pypot's does)."""

    def seen() -> bool:
        server.send(user)
        return user in kinect.tracked_skeleton

    return eventually(seen, timeout_s=10, interval_s=0.05)


def test_parse_gives_pypots_skeleton() -> None:
    values = ",".join(repr(float(v)) for v in joints_array(3).flat).encode()
    header = json.dumps({"shape": [20, 10], "timestamp": 12.0, "user_index": 3}).encode()
    skeleton = parse_skeleton(header, values)
    assert isinstance(skeleton, Skeleton) and skeleton.joints == JOINTS
    assert (skeleton.timestamp, skeleton.user_id) == (12.0, 3)
    elbow = skeleton.elbow_left  # the 6th joint: position divided by w
    assert tuple(elbow.position) == (5.0, 3.0, 2.0)
    assert (elbow.pixel_coordinate.x, elbow.pixel_coordinate.y) == (50.0, 5.0)
    assert elbow.orientation.w == 1.0 and skeleton.as_dict()["joints"]["head"]["position"] == [
        3.0,
        3.0,
        2.0,
    ]


@pytest.mark.parametrize(
    ("header", "values", "said"),
    [
        (b"not json", b"1", "not a skeleton header"),
        (b'{"shape": [20, 9], "timestamp": 0, "user_index": 1}', b"1", r"of shape \[20, 9\]"),
        (b'{"shape": [20, 10], "timestamp": 0, "user_index": 1}', b"1,2", "comma-separated"),
    ],
)
def test_broken_messages_are_value_errors(header: bytes, values: bytes, said: str) -> None:
    with pytest.raises(ValueError, match=said):
        parse_skeleton(header, values)


def test_tracked_skeleton_holds_each_users_latest(server: FakeServer) -> None:
    with KinectSensor("kinect", "127.0.0.1", server.port) as kinect:
        assert kinect.tracked_skeleton == {}  # nobody yet: pypot's empty dict, no wait
        assert sent_until_seen(server, kinect, 1)
        assert sent_until_seen(server, kinect, 2)
        assert set(kinect.tracked_skeleton) == {1, 2}
        server.send(1, timestamp=9.0)
        assert eventually(lambda: kinect.tracked_skeleton[1].timestamp == 9.0)
        kinect.remove_user(1)
        assert set(kinect.tracked_skeleton) == {2}
        kinect.remove_all_users()
        assert kinect.tracked_skeleton == {}


def test_a_broken_message_is_said_once_and_the_stream_goes_on(
    server: FakeServer, caplog: pytest.LogCaptureFixture
) -> None:
    with caplog.at_level(logging.WARNING), KinectSensor("kinect", "127.0.0.1", server.port) as k:
        assert sent_until_seen(server, k, 1)
        server.send(5, array=np.full((20, 10), np.nan))
        server.send(6, array=np.ones((20, 9)))
        assert eventually(lambda: k.health().errors >= 2)
        assert sent_until_seen(server, k, 7)
        assert 5 not in k.tracked_skeleton and 6 not in k.tracked_skeleton
    said = [r for r in caplog.records if r.name == "poppy_core.sensors.base"]
    assert len(said) == 1 and "NaN" in said[0].getMessage()


def _config(entry: dict[str, Any]) -> RobotConfig:
    data = load_profile("torso").to_pypot_dict()
    data["sensors"] = {"kinect": entry}
    return RobotConfig.from_dict(data, source="robot.json")


def test_a_pypot_config_entry_reads_through_rest(server: FakeServer) -> None:
    entry = {"type": "KinectSensor", "addr": "127.0.0.1", "port": server.port}
    with from_config(_config(entry), sim=True) as robot:
        assert sent_until_seen(server, robot.kinect, 4)
        with rest(robot) as client:
            value = client.get("/sensors/kinect/registers/tracked_skeleton/value.json").json()
    (skeleton,) = value["tracked_skeleton"].values()
    assert skeleton["user_id"] == 4 and set(skeleton["joints"]) == set(JOINTS)


@pytest.mark.parametrize(
    ("entry", "said"),
    [
        ({"type": "KinectSensor", "port": 9999}, "KinectSensor needs its 'addr' key"),
        ({"type": "KinectSensor", "addr": "pc"}, "the server's TCP port"),
        ({"type": "KinectSensor", "addr": "pc", "port": "9999"}, "the server's TCP port"),
        ({"type": "ArduinoSensor", "port": 9999}, "must be a serial device"),
    ],
)
def test_bad_entries_are_one_line(entry: dict[str, Any], said: str) -> None:
    with pytest.raises(ConfigError, match=said) as caught:
        _config(entry)
    assert "\n" not in str(caught.value)
