"""A ROS 2 client written from rmw_zenoh's design, for the tests: no ROS, no poppy wire code.

Keys ``<domain>/<name>/<DDS type>/<RIHS01 hash>``; samples and queries carry rmw_zenoh's
attachment (int64 sequence, int64 ns timestamp, 16-byte GID as a zenoh-ext sequence); CDR by
rosbags. The hashes are the published ones (``ros2 interface`` / rmw_zenoh keys): JointState's
and Trigger's are quoted by third parties; SetBool's is computed the way ROS 2 hashes a service
(checked on example_interfaces/srv/SetBool, whose published hash is a69782e5...).
"""

from __future__ import annotations

import struct
import threading
import time
from typing import Any

import zenoh
import zenoh.ext
from rosbags.typesys import Stores, get_typestore
from rosbags.typesys.store import Typestore

HASHES = {
    "sensor_msgs/msg/JointState": (
        "RIHS01_a13ee3a330e346c9d87b5aa18d24e11690752bd33a0350f11c5882bc9179260e"
    ),
    "std_msgs/msg/String": (
        "RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18"
    ),
    "trajectory_msgs/msg/JointTrajectory": (
        "RIHS01_179b33eba59d676f6d967ac71fe35e7ca2f64b2f3928f4a018cec115e213796e"
    ),
    # rosbags' hashes of the Jazzy definitions (it gives JointState's published one above)
    "tf2_msgs/msg/TFMessage": (
        "RIHS01_e369d0f05a23ae52508854b66f6aa0437f3449d652e8cbf22d5abe85d020f087"
    ),
    "diagnostic_msgs/msg/DiagnosticArray": (
        "RIHS01_5a8a36efb05fb25070fa0fb3810290c0e6cd4862b54a8fb975a1ee8dc55a333e"
    ),
    "sensor_msgs/msg/CompressedImage": (
        "RIHS01_15640771531571185e2efc8a100baf923961a4d15d5569652e6cb6691e8e371a"
    ),
    "sensor_msgs/msg/Imu": (
        "RIHS01_7d9a00ff131080897a5ec7e26e315954b8eae3353c3f995c55faf71574000b5b"
    ),
    "std_srvs/srv/SetBool": (
        "RIHS01_abe9e4bb6b41b40e6789712c00ec8871923e089af3f667a79992a428cff2da0a"
    ),
    "std_srvs/srv/Trigger": (
        "RIHS01_eeff2cd6fa5ad9d27cdf4dec64818317839b62f212a91e6b5304b634b2062c5f"
    ),
}
ATTACHMENT = struct.Struct("<qqB16s")
CLIENT_GID = bytes(range(100, 116))


def dds(name: str) -> str:
    package, kind, base = name.split("/")
    return f"{package}::{kind}::dds_::{base}_"


def key(domain: int, name: str, typename: str) -> str:
    return f"{domain}/{name.strip('/')}/{dds(typename)}/{HASHES[typename]}"


def store() -> Typestore:
    typestore = get_typestore(Stores.ROS2_JAZZY)
    from rosbags.typesys.base import Nodetype  # type: ignore[attr-defined]

    def base(name: str, typ: str) -> Any:
        return (name, (Nodetype.BASE, (typ, 0)))

    answer = [base("success", "bool"), base("message", "string")]
    wanted = {
        "std_srvs/srv/SetBool_Request": ([], [base("data", "bool")]),
        "std_srvs/srv/SetBool_Response": ([], answer),
        "std_srvs/srv/Trigger_Request": ([], []),
        "std_srvs/srv/Trigger_Response": ([], answer),
    }
    missing = {k: v for k, v in wanted.items() if k not in typestore.fielddefs}
    if missing:
        typestore.register(missing)
    return typestore


TYPES = store()


def attachment(sequence: int) -> bytes:
    return ATTACHMENT.pack(sequence, time.time_ns(), 16, CLIENT_GID)


def read_attachment(data: bytes) -> tuple[int, int, bytes]:
    sequence, stamp, size, gid = ATTACHMENT.unpack(data)
    assert size == 16
    return sequence, stamp, gid


def encode(message: Any, typename: str) -> bytes:
    return bytes(TYPES.serialize_cdr(message, typename, little_endian=True))


def decode(data: bytes, typename: str) -> Any:
    return TYPES.deserialize_cdr(data, typename)


def msg(typename: str, /, **fields: Any) -> Any:
    return TYPES.types[typename](**fields)


class Collector:
    """Samples of one key, decoded, with their attachments."""

    def __init__(self, session: zenoh.Session, domain: int, name: str, typename: str) -> None:
        self.key = key(domain, name, typename)
        self.typename = typename
        self.samples: list[tuple[str, Any, tuple[int, int, bytes]]] = []
        self._lock = threading.Lock()
        self._sub = session.declare_subscriber(self.key, self._on)

    def _on(self, sample: zenoh.Sample) -> None:
        assert sample.attachment is not None
        item = (
            str(sample.key_expr),
            decode(sample.payload.to_bytes(), self.typename),
            read_attachment(sample.attachment.to_bytes()),
        )
        with self._lock:
            self.samples.append(item)

    def snapshot(self) -> list[tuple[str, Any, tuple[int, int, bytes]]]:
        with self._lock:
            return list(self.samples)

    def close(self) -> None:
        self._sub.undeclare()  # type: ignore[no-untyped-call]


class Client:
    """A publisher-and-caller of a ROS 2 node's topics and services over rmw_zenoh's wire."""

    def __init__(self, session: zenoh.Session, domain: int = 0) -> None:
        self.session = session
        self.domain = domain
        self.sequence = 0
        self._publishers: dict[str, Any] = {}

    def publish(self, name: str, typename: str, message: Any) -> None:
        k = key(self.domain, name, typename)
        if k not in self._publishers:
            self._publishers[k] = self.session.declare_publisher(k)
        self.sequence += 1
        self._publishers[k].put(encode(message, typename), attachment=attachment(self.sequence))

    def call(self, name: str, typename: str, request: Any) -> tuple[Any, tuple[int, int, bytes]]:
        self.sequence += 1
        replies = list(
            self.session.get(
                key(self.domain, name, typename),
                payload=encode(request, f"{typename}_Request"),
                attachment=attachment(self.sequence),
                timeout=10.0,
            )
        )
        assert replies, f"no reply from {name}"
        reply = replies[0].ok
        assert reply is not None, replies[0].err
        assert reply.attachment is not None
        response = decode(reply.payload.to_bytes(), f"{typename}_Response")
        return response, read_attachment(reply.attachment.to_bytes())

    def latched(self, name: str, typename: str) -> list[Any]:
        """What a transient-local subscription gets on joining (rmw_zenoh: an advanced
        subscriber asking the publishers' caches)."""
        got: list[Any] = []
        subscriber = zenoh.ext.declare_advanced_subscriber(
            self.session,
            key(self.domain, name, typename),
            lambda s: got.append(decode(s.payload.to_bytes(), typename)),
            history=zenoh.ext.HistoryConfig(detect_late_publishers=True),
        )
        self._publishers[f"latched {name}"] = subscriber
        return got

    def tokens(self) -> list[str]:
        return [str(r.ok.key_expr) for r in self.session.liveliness().get("@ros2_lv/**") if r.ok]

    def close(self) -> None:
        for declared in self._publishers.values():
            declared.undeclare()
        self._publishers = {}
