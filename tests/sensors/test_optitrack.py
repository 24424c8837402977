"""OptiTrackClient and the OptiTrack bridge: a fake Motive on loopback answers NatNet commands
and streams frames built with ``struct`` from the NatNet description (NatNet 3.1, 4.0, 4.1)."""

from __future__ import annotations

import logging
import math
import pickle
import socket
import struct
import threading
from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest

from poppy_core import from_config
from poppy_core.errors import ConfigError
from poppy_core.robot import RobotConfig, load_profile
from poppy_core.sensors import natnet
from poppy_core.sensors.optibridge import OptiBridgeClient, OptiBridgeServer, decode, encode
from poppy_core.sensors.optitrack import (
    MULTICAST_GROUP,
    OptiTrackClient,
    TrackedObject,
    quat2euler,
    tracked,
)
from tests.helpers.sensor_rest import rest
from tests.helpers.waiting import eventually

LOOPBACK = "127.0.0.1"
VERSIONS = [(3, 1), (4, 0), (4, 1)]
Body = tuple[int, tuple[float, float, float], tuple[float, float, float, float], bool]


def free_port(kind: int = socket.SOCK_DGRAM) -> int:
    with socket.socket(socket.AF_INET, kind) as probe:
        probe.bind((LOOPBACK, 0))
        return int(probe.getsockname()[1])


def message(message_id: int, payload: bytes) -> bytes:
    return struct.pack("<HH", message_id, len(payload)) + payload


def server_info(version: tuple[int, int]) -> bytes:
    payload = b"Motive".ljust(256, b"\0") + bytes([3, 1, 0, 0]) + bytes([*version, 0, 0])
    return message(natnet.NAT_SERVERINFO, payload)


def counted(count: int, body: bytes, version: tuple[int, int]) -> bytes:
    """A section: its count, (4.1+) its byte count, then its items."""
    size = struct.pack("<i", len(body)) if version >= (4, 1) else b""
    return struct.pack("<i", count) + size + body


def frame(number: int, bodies: list[Body], version: tuple[int, int]) -> bytes:
    markers = b"all\0" + struct.pack("<i6f", 2, 1, 2, 3, 4, 5, 6)
    payload = struct.pack("<i", number) + counted(1, markers, version)
    payload += counted(1, struct.pack("<3f", 7, 8, 9), version)
    rigid = b"".join(
        struct.pack("<i3f4ffh", i, *pos, *quat, 0.001, 1 if valid else 0)
        for i, pos, quat, valid in bodies
    )
    payload += counted(len(bodies), rigid, version)
    payload += counted(0, b"", version) + b"\x00" * 24  # skeletons, then what is not read
    return message(natnet.NAT_FRAMEOFDATA, payload)


def rigid_body_description(body_id: int, name: str, version: tuple[int, int]) -> bytes:
    out = name.encode() + b"\0" + struct.pack("<ii3f", body_id, -1, 0, 0, 0)
    out += struct.pack("<i6f2i", 2, 0.1, 0, 0, 0, 0.1, 0, 0, 0)
    if version[0] >= 4:
        out += b"m1\0m2\0"
    return out


def model_def(names: dict[int, str], version: tuple[int, int]) -> bytes:
    sets = [(0, b"all\0" + struct.pack("<i", 2) + b"m1\0m2\0")]
    sets += [(1, rigid_body_description(i, n, version)) for i, n in names.items()]
    if version >= (4, 1):
        sets.append((4, b"\x07" * 21))  # a device: skipped by its size
    payload = struct.pack("<i", len(sets))
    for kind, body in sets:
        payload += struct.pack("<i", kind)
        if version >= (4, 1):
            payload += struct.pack("<i", len(body))
        payload += body
    return message(natnet.NAT_MODELDEF, payload)


class FakeMotive:
    """Motive's side on loopback: answers NAT_CONNECT and NAT_REQUEST_MODELDEF, streams frames
    to the client's data port (unicast)."""

    def __init__(self, version: tuple[int, int] = (4, 1)) -> None:
        self.version = version
        self.names: dict[int, str] = {1: "robot", 2: "ball"}
        self.socket = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.socket.bind((LOOPBACK, 0))
        self.socket.settimeout(0.1)
        self.port = int(self.socket.getsockname()[1])
        self.data_port = free_port()
        self.asked: list[int] = []
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._serve, daemon=True)
        self._thread.start()

    def _serve(self) -> None:
        while not self._stop.is_set():
            try:
                packet, source = self.socket.recvfrom(65536)
            except (TimeoutError, OSError):
                continue
            message_id = struct.unpack_from("<H", packet)[0]
            self.asked.append(message_id)
            if message_id == natnet.NAT_CONNECT:
                self.socket.sendto(server_info(self.version), source)
            elif message_id == natnet.NAT_REQUEST_MODELDEF:
                self.socket.sendto(model_def(self.names, self.version), source)

    def send(self, packet: bytes) -> None:
        self.socket.sendto(packet, (LOOPBACK, self.data_port))

    def stream(self, bodies: list[Body], number: int = 1) -> None:
        self.send(frame(number, bodies, self.version))

    def close(self) -> None:
        self._stop.set()
        self._thread.join(2)
        self.socket.close()


@pytest.fixture
def motive() -> Iterator[FakeMotive]:
    made = FakeMotive()
    yield made
    made.close()


def client(motive: FakeMotive, names: tuple[str, ...] = ("robot",), **kw: Any) -> OptiTrackClient:
    return OptiTrackClient(
        "optitrack",
        LOOPBACK,
        motive.port,
        names,
        data_port=motive.data_port,
        multicast=None,
        local_addr=LOOPBACK,
        **kw,
    )


ROBOT: Body = (1, (0.5, 1.0, -2.0), (0.0, 0.0, 0.0, 1.0), True)
BALL: Body = (2, (3.0, 0.1, 0.2), (0.0, 0.0, 0.0, 1.0), True)


def streamed_until(motive: FakeMotive, opti: Any, name: str, bodies: list[Body]) -> bool:
    """Motive streams until the client holds ``name`` (the first frames come before the
    client learnt the version and the names, and are dropped as a NatNet client does)."""

    def seen() -> bool:
        motive.stream(bodies)
        return name in opti.tracked_objects

    return eventually(seen, timeout_s=10, interval_s=0.02)


@pytest.mark.parametrize("version", VERSIONS)
def test_frames_and_model_definitions_parse_per_version(version: tuple[int, int]) -> None:
    number, bodies = natnet.parse_frame(frame(42, [ROBOT, BALL], version)[4:], version)
    assert number == 42 and [b.id for b in bodies] == [1, 2]
    assert bodies[0].position == (0.5, 1.0, -2.0) and bodies[0].quaternion == (0, 0, 0, 1)
    assert bodies[0].valid and math.isclose(bodies[0].mean_error, 0.001, rel_tol=1e-6)
    names = natnet.parse_model_def(model_def({1: "robot", 7: "ball"}, version)[4:], version)
    assert names == {1: "robot", 7: "ball"}


def test_broken_and_unsupported_messages_are_value_errors() -> None:
    whole = frame(1, [ROBOT], (4, 1))[4:]
    with pytest.raises(ValueError, match="cut short"):
        natnet.parse_frame(whole[:40], (4, 1))
    with pytest.raises(ValueError, match=r"NatNet 2\.9; poppy reads NatNet 3\.0 to 4\.x"):
        natnet.parse_frame(whole, (2, 9))
    with pytest.raises(ValueError, match="announcing 300 bytes"):
        natnet.split(struct.pack("<HH", 7, 300) + b"\0" * 10)
    assert natnet.parse_server_info(server_info((4, 1))[4:]) == ("Motive", (4, 1))


def test_orientation_is_pypots_yaw_pitch_roll() -> None:
    half = math.radians(30) / 2
    assert np.allclose(quat2euler((0, math.sin(half), 0, math.cos(half))), (math.radians(30), 0, 0))
    assert np.allclose(quat2euler((0, 0, math.sin(half), math.cos(half))), (0, math.radians(30), 0))
    assert np.allclose(quat2euler((math.sin(half), 0, 0, math.cos(half))), (0, 0, math.radians(30)))


@pytest.mark.parametrize("version", VERSIONS)
def test_the_named_objects_are_tracked(version: tuple[int, int]) -> None:
    motive = FakeMotive(version)
    try:
        with client(motive) as opti:
            assert opti.tracked_objects == {}  # nothing yet: pypot's empty dict, no wait
            assert streamed_until(motive, opti, "robot", [ROBOT, BALL])
            obj = opti.tracked_objects["robot"]
            assert isinstance(obj, TrackedObject) and set(opti.tracked_objects) == {"robot"}
            assert list(obj.position) == [0.5, 1.0, -2.0] and list(obj.orientation) == [0, 0, 0]
            assert opti.natnet_version == version and opti.server_name == "Motive"
    finally:
        motive.close()


def test_multicast_frames_are_read_on_the_group_joined(motive: FakeMotive) -> None:
    """Motive's default mode. The frames go to the group on the loopback interface with a TTL
    of 0: they never leave the machine."""
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:
        group = socket.inet_aton(MULTICAST_GROUP) + socket.inet_aton(LOOPBACK)
        try:
            probe.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP, group)
        except OSError:
            pytest.skip("no multicast on this machine's loopback")
    sender = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sender.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, 0)
    sender.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_IF, socket.inet_aton(LOOPBACK))
    sender.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_LOOP, 1)
    opti = OptiTrackClient(
        "optitrack",
        LOOPBACK,
        motive.port,
        ("robot",),
        data_port=motive.data_port,
        multicast=MULTICAST_GROUP,
        local_addr=LOOPBACK,
    )
    try:
        with opti:

            def seen() -> bool:
                packet = frame(1, [ROBOT], motive.version)
                sender.sendto(packet, (MULTICAST_GROUP, motive.data_port))
                return "robot" in opti.tracked_objects

            assert eventually(seen, timeout_s=10, interval_s=0.02), opti.health().last_error
            assert natnet.NAT_KEEPALIVE not in motive.asked  # multicast: no keep-alives
    finally:
        sender.close()


def test_recent_objects_are_those_received_in_the_last_20_ms(motive: FakeMotive) -> None:
    with client(motive, ("robot", "ball")) as opti:
        assert streamed_until(motive, opti, "robot", [ROBOT])
        assert eventually(lambda: opti.recent_tracked_objects == {}, timeout_s=10)
        lost: Body = (1, (9.0, 9.0, 9.0), (0, 0, 0, 1), False)  # Motive lost it: not kept
        assert streamed_until(motive, opti, "ball", [lost, BALL])
        assert list(opti.tracked_objects["robot"].position) == [0.5, 1.0, -2.0]


def test_a_body_added_in_motive_asks_for_the_names_again(motive: FakeMotive) -> None:
    cup: Body = (3, (1.0, 2.0, 3.0), (0, 0, 0, 1), True)
    with client(motive, ("robot", "cup")) as opti:
        assert streamed_until(motive, opti, "robot", [ROBOT])
        asked = motive.asked.count(natnet.NAT_REQUEST_MODELDEF)
        motive.names[3] = "cup"
        assert streamed_until(motive, opti, "cup", [ROBOT, cup])
        assert motive.asked.count(natnet.NAT_REQUEST_MODELDEF) > asked
        assert natnet.NAT_KEEPALIVE in motive.asked  # unicast: Motive keeps sending to us


def test_a_broken_packet_is_said_once_and_the_stream_goes_on(
    motive: FakeMotive, caplog: pytest.LogCaptureFixture
) -> None:
    with caplog.at_level(logging.WARNING), client(motive) as opti:
        assert streamed_until(motive, opti, "robot", [ROBOT])
        motive.send(frame(2, [ROBOT], motive.version)[:30])
        motive.send(b"\x07")
        assert eventually(lambda: opti.health().errors >= 2)
        moved: Body = (1, (7.0, 7.0, 7.0), (0, 0, 0, 1), True)
        assert eventually(
            lambda: motive.stream([moved]) or opti.tracked_objects["robot"].position[0] == 7.0
        )
    said = [r for r in caplog.records if r.name == "poppy_core.sensors.base"]
    assert len(said) == 1 and "NatNet" in said[0].getMessage()


def test_an_old_natnet_is_refused_in_one_line(caplog: pytest.LogCaptureFixture) -> None:
    motive = FakeMotive((2, 10))
    try:
        with caplog.at_level(logging.WARNING), client(motive) as opti:
            opti.start()
            assert eventually(lambda: "poppy reads NatNet 3.0" in opti.health().last_error)
            assert opti.natnet_version is None
    finally:
        motive.close()


def test_the_bridge_passes_the_named_objects_on_as_json(motive: FakeMotive) -> None:
    bridge_port = free_port(socket.SOCK_STREAM)
    server = OptiBridgeServer(
        "bridge",
        LOOPBACK,
        motive.port,
        ("robot", "ball"),
        bridge_host=LOOPBACK,
        bridge_port=bridge_port,
        data_port=motive.data_port,
        multicast=None,
        local_addr=LOOPBACK,
        recent_s=1.0,
    )
    with server, OptiBridgeClient("opti", LOOPBACK, bridge_port, ("ball",)) as far:
        server.start()
        far.start()

        def arrived() -> bool:
            motive.stream([ROBOT, BALL])
            return "ball" in far.tracked_objects

        assert eventually(arrived, timeout_s=10, interval_s=0.02)
        assert set(far.recent_tracked_objects) == {"ball"}  # the client keeps what it names
        assert list(far.tracked_objects["ball"].position) == pytest.approx([3.0, 0.1, 0.2])
        assert server.published > 0


def test_a_pickled_bridge_message_is_refused(caplog: pytest.LogCaptureFixture) -> None:
    zmq = pytest.importorskip("zmq")
    port = free_port(socket.SOCK_STREAM)
    pub = zmq.Context.instance().socket(zmq.PUB)
    pub.setsockopt(zmq.LINGER, 0)
    pub.bind(f"tcp://{LOOPBACK}:{port}")
    try:
        with caplog.at_level(logging.WARNING), OptiBridgeClient("o", LOOPBACK, port, ("a",)) as far:
            far.start()

            def refused() -> bool:
                pub.send(pickle.dumps({"a": None}))
                return far.health().errors > 0

            assert eventually(refused, timeout_s=10, interval_s=0.05)
            assert "pickled" in far.health().last_error and far.tracked_objects == {}
    finally:
        pub.close()


def test_the_bridge_message_round_trips() -> None:
    obj = tracked((1.0, 2.0, 3.0), (0.0, 0.0, 0.0, 1.0))
    (back,) = decode(encode({"a": obj})).values()
    assert back.as_dict() == obj.as_dict()
    with pytest.raises(ValueError, match="not a tracked object"):
        decode(b'{"a": {"position": [1]}}')


def _config(entry: dict[str, Any]) -> RobotConfig:
    data = load_profile("torso").to_pypot_dict()
    data["sensors"] = {"optitrack": entry}
    return RobotConfig.from_dict(data, source="robot.json")


def test_a_pypot_config_entry_reads_through_rest(motive: FakeMotive) -> None:
    entry = {
        "type": "OptiTrackClient",
        "addr": LOOPBACK,
        "port": motive.port,
        "obj_names": ["robot"],
        "data_port": motive.data_port,
        "multicast": False,
        "local_addr": LOOPBACK,
    }
    with from_config(_config(entry), sim=True) as robot:
        assert streamed_until(motive, robot.optitrack, "robot", [ROBOT])
        with rest(robot) as http:
            url = "/sensors/optitrack/registers/tracked_objects/value.json"
            value = http.get(url).json()
    assert value["tracked_objects"]["robot"]["position"] == [0.5, 1.0, -2.0]


def test_a_bridge_server_in_a_config_serves_unread(motive: FakeMotive) -> None:
    port = free_port(socket.SOCK_STREAM)
    data = load_profile("torso").to_pypot_dict()
    data["sensors"] = {
        "bridge": {
            "type": "OptiBridgeServer",
            "addr": LOOPBACK,
            "port": motive.port,
            "obj_names": ["robot", "ball"],
            "data_port": motive.data_port,
            "multicast": False,
            "local_addr": LOOPBACK,
            "bridge_host": LOOPBACK,
            "bridge_port": port,
        },
        "far": {"type": "OptiBridgeClient", "addr": LOOPBACK, "port": port, "obj_names": ["ball"]},
    }
    config = RobotConfig.from_dict(data, source="robot.json")
    with from_config(config, sim=True) as robot:
        assert robot.bridge.running  # started with the robot: it serves other machines
        assert streamed_until(motive, robot.far, "ball", [ROBOT, BALL])
        assert set(robot.far.tracked_objects) == {"ball"}


@pytest.mark.parametrize(
    ("entry", "said"),
    [
        ({"type": "OptiTrackClient", "obj_names": ["a"]}, "needs its 'addr' key"),
        ({"type": "OptiTrackClient", "addr": "pc"}, "needs its 'obj_names' key"),
        ({"type": "OptiTrackClient", "addr": "pc", "obj_names": ["a"], "port": 3883}, "VRPN"),
        ({"type": "OptiTrackClient", "addr": "pc", "obj_names": ["a"], "port": "x"}, "1510"),
        (
            {"type": "OptiTrackClient", "addr": "pc", "obj_names": ["a"], "multicast": "10.0.0.1"},
            "multicast group",
        ),
        (
            {"type": "OptiTrackClient", "addr": "pc", "obj_names": ["a"], "local_addr": "eth0"},
            "IPv4",
        ),
        (
            {"type": "OptiBridgeServer", "addr": "pc", "obj_names": ["a"], "bridge_host": "h"},
            "'bridge_port'",
        ),
        ({"type": "OptiBridgeClient", "addr": "pc", "obj_names": ["a"]}, "the server's TCP port"),
    ],
)
def test_bad_entries_are_one_line(entry: dict[str, Any], said: str) -> None:
    with pytest.raises(ConfigError, match=said) as caught:
        _config(entry)
    assert "\n" not in str(caught.value)
