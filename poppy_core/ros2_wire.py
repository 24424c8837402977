"""rmw_zenoh's wire (the node of ``poppy serve --ros2``): keys, tokens, QoS strings, attachments.

No Zenoh and no ROS here: strings and bytes only, so the node and its tests share nothing but
these rules. Source of the facts: ros2/rmw_zenoh (docs/design.md and rmw_zenoh_cpp/src/detail:
liveliness_utils.cpp, qos.cpp, attachment_helpers.cpp, rmw_publisher_data.cpp,
rmw_service_data.cpp), read for the format; nothing copied.

- Data key of a topic or service: ``<domain>/<fully qualified name without its leading
  slash>/<DDS type name>/<RIHS01 type hash>``.
- Liveliness token of an entity: ``@ros2_lv/<domain>/<session zid>/<node id>/<entity id>/<kind>/
  <enclave>/<namespace>/<node name>`` then, for a topic or service, ``/<name>/<type>/<hash>/<qos>``
  (every ``/`` inside a part written ``%``; kinds NN node, MP publisher, MS subscription,
  SS service server, SC service client).
- QoS part: ``reliability:durability:history,depth:deadline_s,deadline_ns:lifespan_s,lifespan_ns:
  liveliness,lease_s,lease_ns``, each number left empty when it is rmw_zenoh's default
  (reliable, volatile, keep last, depth 42, infinite durations, automatic liveliness).
- Attachment of every sample and reply: int64 sequence number, int64 source timestamp (ns since
  the epoch), then the 16-byte GID as a sequence (LEB128 length 16, then the bytes): zenoh-ext's
  serialisation of ``(int64, int64, std::array<uint8_t, 16>)``, little-endian.
"""

from __future__ import annotations

import hashlib
import re
import struct
from dataclasses import dataclass, field

from poppy_core.errors import ConfigError
from poppy_core.zenoh_wire import ZenohSettings

ADMIN_SPACE = "@ros2_lv"
NODE, PUBLISHER, SUBSCRIPTION, SERVICE, CLIENT = "NN", "MP", "MS", "SS", "SC"
SLASH = "%"
GID_SIZE = 16
_ATTACHMENT = struct.Struct("<qqB16s")

# rmw's QoS policy numbers (rmw/types.h)
RELIABLE, BEST_EFFORT = 1, 2
TRANSIENT_LOCAL, VOLATILE = 1, 2
KEEP_LAST, KEEP_ALL = 1, 2
DEFAULT_DEPTH = 42

ROUTER = "tcp/127.0.0.1:7447"
"""rmw_zenoh's default: its sessions connect to the router on the same machine."""
_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]*")
MAX_DOMAIN = 232
"""ROS 2's highest domain ID (REP 2005's range for DDS; rmw_zenoh takes the same numbers)."""


@dataclass(frozen=True)
class Qos:
    """The QoS a token declares (only what differs from rmw_zenoh's default is written)."""

    reliability: int = RELIABLE
    durability: int = VOLATILE
    history: int = KEEP_LAST
    depth: int = DEFAULT_DEPTH

    def keyexpr(self) -> str:
        """The token's QoS part."""
        reliability = "" if self.reliability == RELIABLE else str(self.reliability)
        durability = "" if self.durability == VOLATILE else str(self.durability)
        history = "" if self.history == KEEP_LAST else str(self.history)
        depth = "" if self.depth == DEFAULT_DEPTH else str(self.depth)
        return f"{reliability}:{durability}:{history},{depth}:,:,:,,"


DEFAULT_QOS = Qos(depth=10)
"""rclcpp's default publisher and subscription QoS (keep last 10, reliable, volatile)."""
LATCHED_QOS = Qos(durability=TRANSIENT_LOCAL, depth=1)
"""robot_state_publisher's ``robot_description`` and tf2's ``tf_static``."""
TF_QOS = Qos(depth=100)
"""tf2's dynamic broadcaster."""
SENSOR_QOS = Qos(reliability=BEST_EFFORT, depth=5)
"""rclcpp's SensorDataQoS (cameras)."""
SERVICE_QOS = Qos(depth=10)
"""rmw's services default."""


def check_domain(domain: int) -> int:
    """``domain`` when it is a ROS 2 domain ID (0 to 232).

    Raises:
        ConfigError: another value.
    """
    if isinstance(domain, bool) or not isinstance(domain, int) or not 0 <= domain <= MAX_DOMAIN:
        raise ConfigError(
            f"{domain!r} is not a ROS 2 domain ID: use 0 to {MAX_DOMAIN} (ROS_DOMAIN_ID)",
            field="ros_domain",
        )
    return domain


def check_namespace(namespace: str) -> str:
    """The namespace as ROS 2 writes it: ``/`` or ``/a/b`` (a leading slash added).

    Raises:
        ConfigError: a part that is not a ROS name (letters, digits, ``_``; not a digit first).
    """
    parts = [p for p in str(namespace).strip("/").split("/") if p != ""]
    for part in parts:
        if not _NAME.fullmatch(part) or "__" in part:
            raise ConfigError(
                f"{namespace!r} is not a ROS 2 namespace: use /name or /a/b with letters, digits "
                "and single '_', not starting with a digit",
                field="ros_namespace",
            )
    return "/" + "/".join(parts)


def check_node_name(name: str) -> str:
    """``name`` when it is a ROS 2 node name.

    Raises:
        ConfigError: another name.
    """
    if not _NAME.fullmatch(name) or "__" in name:
        raise ConfigError(
            f"{name!r} is not a ROS 2 node name: letters, digits and '_', not starting with a "
            "digit",
            field="ros_node",
        )
    return name


def node_name_from(robot_name: str) -> str:
    """A ROS 2 node name made from a robot's name (``jr-1`` -> ``jr_1``)."""
    name = re.sub(r"[^A-Za-z0-9_]", "_", robot_name).strip("_")
    name = re.sub(r"_+", "_", name)
    if not name or not name[0].isalpha():
        name = f"poppy_{name}".rstrip("_")
    return name


def fully_qualified(namespace: str, node: str, name: str) -> str:
    """The absolute name of ``name`` (``~/x``: private to the node; ``x``: in the namespace)."""
    if name.startswith("/"):
        return name
    base = namespace.rstrip("/")
    if name.startswith("~"):
        return f"{base}/{node}{name[1:]}"
    return f"{base}/{name}"


def data_key(domain: int, name: str, dds_type: str, type_hash: str) -> str:
    """The key a topic is published on, or a service answered on."""
    return f"{domain}/{name.strip('/')}/{dds_type}/{type_hash}"


def name_of_key(key: str) -> str:
    """The topic or service name of a ``data_key`` (``0/jr1/stop/T/H`` -> ``/jr1/stop``)."""
    return "/" + "/".join(str(key).split("/")[1:-2])


def mangle(part: str) -> str:
    """A name as one key chunk (``/`` written ``%``)."""
    return part.replace("/", SLASH)


def token_key(
    domain: int,
    zid: str,
    node_id: int,
    entity_id: int,
    kind: str,
    namespace: str,
    node: str,
    *,
    enclave: str = "/",
    topic: tuple[str, str, str, Qos] | None = None,
) -> str:
    """The liveliness token of one entity (``topic``: name, DDS type, hash and QoS)."""
    parts = [
        ADMIN_SPACE,
        str(domain),
        zid,
        str(node_id),
        str(entity_id),
        kind,
        mangle(enclave),
        mangle(namespace),
        mangle(node),
    ]
    if topic is not None:
        name, dds_type, type_hash, qos = topic
        parts += [mangle(name), mangle(dds_type), mangle(type_hash), qos.keyexpr()]
    return "/".join(parts)


@dataclass(frozen=True)
class Ros2Settings:
    """The node's place in the ROS 2 graph.

    Attributes:
        domain: ROS_DOMAIN_ID (0-232).
        namespace: the node's namespace (``/`` or ``/a/b``).
        node: the node's name (the robot's name made a ROS name when None).
        zenoh: how the session joins when the fleet's ``--zenoh`` is not served too
            (rmw_zenoh's default: connect to the router on this machine, ``zenohd`` or
            ``ros2 run rmw_zenoh_cpp rmw_zenohd``).
    """

    domain: int = 0
    namespace: str = "/"
    node: str | None = None
    zenoh: ZenohSettings = field(default_factory=lambda: ZenohSettings(connect=(ROUTER,)))

    def __post_init__(self) -> None:
        check_domain(self.domain)
        object.__setattr__(self, "namespace", check_namespace(self.namespace))
        if self.node is not None:
            check_node_name(self.node)


def gid(token: str) -> bytes:
    """The 16-byte GID of an entity, a hash of its token.

    rmw_zenoh hashes the token with XXH3-128; any stable 16 bytes serve the same purpose (the
    GID only names the writer in message infos and service replies), so this is BLAKE2b-128.
    """
    return hashlib.blake2b(token.encode(), digest_size=GID_SIZE).digest()


def attachment(sequence: int, timestamp_ns: int, source_gid: bytes) -> bytes:
    """The attachment of a sample or a reply."""
    return _ATTACHMENT.pack(sequence, timestamp_ns, GID_SIZE, source_gid)


@dataclass(frozen=True)
class Attachment:
    """A decoded attachment."""

    sequence: int
    timestamp_ns: int
    gid: bytes


def read_attachment(data: bytes) -> Attachment:
    """The attachment ``attachment`` made (or a client's request made the same way).

    Raises:
        ConfigError: not 33 bytes of that shape.
    """
    try:
        sequence, stamp, size, source = _ATTACHMENT.unpack(bytes(data))
    except struct.error:
        raise ConfigError(
            f"not an rmw_zenoh attachment ({len(data)} bytes)", field="attachment"
        ) from None
    if size != GID_SIZE:
        raise ConfigError(f"not an rmw_zenoh attachment (GID of {size} bytes)", field="attachment")
    return Attachment(sequence, stamp, source)
