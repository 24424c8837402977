"""The ROS 2 types the node speaks: a rosbags typestore, their DDS names and RIHS01 hashes.

``rosbags`` serialises CDR and hashes type descriptions (REP 2011) without ROS. Its stores hold
the messages; the two services (std_srvs SetBool and Trigger) are registered here from their
fields, and hashed as ROS 2 describes a service since Iron (request, response and event), so
that their hashes are rmw_zenoh's.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache
from typing import TYPE_CHECKING, Any

from poppy_core.extras import require

if TYPE_CHECKING:
    from rosbags.typesys.store import Typestore

JOINT_STATE = "sensor_msgs/msg/JointState"
STRING = "std_msgs/msg/String"
TF_MESSAGE = "tf2_msgs/msg/TFMessage"
DIAGNOSTIC_ARRAY = "diagnostic_msgs/msg/DiagnosticArray"
COMPRESSED_IMAGE = "sensor_msgs/msg/CompressedImage"
IMU = "sensor_msgs/msg/Imu"
JOINT_TRAJECTORY = "trajectory_msgs/msg/JointTrajectory"
SET_BOOL = "std_srvs/srv/SetBool"
TRIGGER = "std_srvs/srv/Trigger"

_SERVICES = {
    SET_BOOL: ((("data", "bool"),), (("success", "bool"), ("message", "string"))),
    TRIGGER: ((), (("success", "bool"), ("message", "string"))),
}
"""Request and response fields of std_srvs' two services (their .srv files, as facts)."""


@dataclass(frozen=True)
class RosType:
    """A message or service type: ``name`` (``pkg/msg/T``), its DDS name and its hash."""

    name: str
    dds: str
    hash: str


@cache
def typestore() -> Typestore:
    """The Jazzy typestore (Kilted's messages hash the same) with the services' requests and
    responses added.

    Raises:
        MissingExtraError: rosbags is not installed (the ``ros2`` extra).
    """
    require("rosbags", extra="ros2")
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS2_JAZZY)
    types: dict[str, Any] = {}
    for name, (request, response) in _SERVICES.items():
        types[f"{name}_Request"] = ([], [_field(*f) for f in request])
        types[f"{name}_Response"] = ([], [_field(*f) for f in response])
    store.register(types)
    return store


@cache
def _service_hashes() -> Typestore:
    """A store that describes each service as ROS 2 hashes it (REP 2011): a struct of its
    request, response and event messages, the event holding a ``ServiceEventInfo`` whose
    ``client_gid`` is ``uint8[16]`` (rosbags' own store has ``char[16]``, from the .msg file,
    which would hash differently: hence a store of its own)."""
    from rosbags.typesys.base import Nodetype  # type: ignore[attr-defined]
    from rosbags.typesys.store import Typestore as Store

    def named(name: str) -> Any:
        return (Nodetype.NAME, name)

    info = "service_msgs/msg/ServiceEventInfo"
    types: dict[str, Any] = {
        "builtin_interfaces/msg/Time": ([], [_field("sec", "int32"), _field("nanosec", "uint32")]),
        info: (
            [],
            [
                _field("event_type", "uint8"),
                ("stamp", named("builtin_interfaces/msg/Time")),
                ("client_gid", (Nodetype.ARRAY, ((Nodetype.BASE, ("uint8", 0)), 16))),
                _field("sequence_number", "int64"),
            ],
        ),
    }
    for name, (request, response) in _SERVICES.items():
        types[f"{name}_Request"] = ([], [_field(*f) for f in request])
        types[f"{name}_Response"] = ([], [_field(*f) for f in response])
        one = Nodetype.SEQUENCE
        types[f"{name}_Event"] = (
            [],
            [
                ("info", named(info)),
                ("request", (one, (named(f"{name}_Request"), 1))),
                ("response", (one, (named(f"{name}_Response"), 1))),
            ],
        )
        types[name] = (
            [],
            [
                ("request_message", named(f"{name}_Request")),
                ("response_message", named(f"{name}_Response")),
                ("event_message", named(f"{name}_Event")),
            ],
        )
    store = Store()
    store.register(types)
    return store


def _field(name: str, base: str) -> Any:
    from rosbags.typesys.base import Nodetype  # type: ignore[attr-defined]

    return (name, (Nodetype.BASE, (base, 0)))


def dds_name(name: str) -> str:
    """``pkg/msg/T`` -> ``pkg::msg::dds_::T_`` (what rmw_zenoh puts in keys and tokens)."""
    package, kind, base = name.split("/")
    return f"{package}::{kind}::dds_::{base}_"


@cache
def ros_type(name: str) -> RosType:
    """The DDS name and RIHS01 hash of a message or service type."""
    store = _service_hashes() if name in _SERVICES else typestore()
    return RosType(name, dds_name(name), store.hash_rihs01(name))


def message(typename: str, /, **fields: Any) -> Any:
    """A message object of type ``typename``."""
    return typestore().types[typename](**fields)


def serialize(value: Any, name: str) -> bytes:
    """CDR (little-endian, with its 4-byte encapsulation header)."""
    return bytes(typestore().serialize_cdr(value, name, little_endian=True))


def deserialize(data: bytes, name: str) -> Any:
    """The message of CDR ``data`` (rosbags raises its ``SerdeError`` on bad bytes)."""
    return typestore().deserialize_cdr(data, name)
