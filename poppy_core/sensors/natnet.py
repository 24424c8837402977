"""NatNet, the protocol OptiTrack's Motive streams: the messages the OptiTrack client reads.

Facts from NaturalPoint's NatNet SDK 4.x Python sample (``NatNetClient.py``, Apache-2.0; read
for the layout, no code taken). Every message is ``message_id`` (uint16) and ``payload size``
(uint16), little-endian, then the payload. Ids: 0 NAT_CONNECT, 1 NAT_SERVERINFO, 4
NAT_REQUEST_MODELDEF, 5 NAT_MODELDEF, 7 NAT_FRAMEOFDATA, 10 NAT_KEEPALIVE. A server info is a
256-byte NUL-padded application name, the application's version (4 bytes) and the NatNet
version (4 bytes: major, minor, build, revision).

poppy reads NatNet 3.0 to 4.x (Motive 2.x and 3.x; 4.1 adds a byte count after each count).
A frame of data: frame number (int32); marker sets (count; each a NUL-terminated name, a
marker count and that many x, y, z float32); the legacy unlabeled markers (count, x, y, z each);
then the rigid bodies (count; each id int32, position x, y, z float32 in metres, orientation
qx, qy, qz, qw float32, mean marker error float32, params int16 whose bit 0 is "tracking
valid"). What follows the rigid bodies (skeletons, labelled markers...) is not read.
A model definition: a count of data sets, each a type int32 (0 marker set, 1 rigid body, 2
skeleton; 4.1+: then its size in bytes) and its description; a rigid body's is its name (NUL
terminated), id, parent id, offset x, y, z, a marker count, the markers' offsets (3 float32
each), their active labels (int32 each) and, from 4.0, their names (NUL-terminated each).
"""

from __future__ import annotations

import struct
from dataclasses import dataclass
from typing import Any

NAT_CONNECT = 0
NAT_SERVERINFO = 1
NAT_REQUEST_MODELDEF = 4
NAT_MODELDEF = 5
NAT_FRAMEOFDATA = 7
NAT_KEEPALIVE = 10

HEADER = struct.Struct("<HH")
SERVER_NAME_BYTES = 256
SUPPORTED_MAJOR = (3, 4)
"""NatNet major versions read (3.0 to 4.x)."""
MAX_COUNT = 100_000
"""More items than this in one message is a broken message, not a real scene."""

_INT = struct.Struct("<i")
_RIGID_BODY = struct.Struct("<i3f4ffh")
_DESCRIPTION_HEAD = struct.Struct("<ii3f")

MARKER_SET, RIGID_BODY, SKELETON = 0, 1, 2


@dataclass(frozen=True)
class RigidBody:
    """One rigid body of a frame: Motive's id, position (m), quaternion (x, y, z, w)."""

    id: int
    position: tuple[float, float, float]
    quaternion: tuple[float, float, float, float]
    mean_error: float
    valid: bool


def request(message_id: int, payload: bytes = b"") -> bytes:
    """A message to the server (``NAT_CONNECT`` carries ``b"Ping\\0"`` as the sample does)."""
    return HEADER.pack(message_id, len(payload)) + payload


def connect_message() -> bytes:
    """NAT_CONNECT, asking for the server info."""
    return request(NAT_CONNECT, b"Ping\0")


def split(packet: bytes) -> tuple[int, bytes]:
    """The id and payload of a message.

    Raises:
        ValueError: shorter than its header or than the size it announces.
    """
    if len(packet) < HEADER.size:
        raise ValueError(f"a NatNet message of {len(packet)} bytes (shorter than its header)")
    message_id, size = HEADER.unpack_from(packet)
    payload = packet[HEADER.size : HEADER.size + size]
    if len(payload) < size:
        raise ValueError(f"a NatNet message announcing {size} bytes carries {len(payload)}")
    return message_id, payload


def parse_server_info(payload: bytes) -> tuple[str, tuple[int, int]]:
    """The application's name and its NatNet (major, minor) version.

    Raises:
        ValueError: too short.
    """
    if len(payload) < SERVER_NAME_BYTES + 8:
        raise ValueError(f"a NatNet server info of {len(payload)} bytes (needs 264)")
    name = payload[:SERVER_NAME_BYTES].split(b"\0", 1)[0].decode("utf-8", "replace")
    major, minor = payload[SERVER_NAME_BYTES + 4], payload[SERVER_NAME_BYTES + 5]
    return name, (major, minor)


def check_version(version: tuple[int, int]) -> None:
    """Raises ValueError for a NatNet version poppy does not read."""
    if version[0] not in SUPPORTED_MAJOR:
        raise ValueError(
            f"Motive streams NatNet {version[0]}.{version[1]}; poppy reads NatNet 3.0 to 4.x "
            "(set the stream's version in Motive's streaming settings)"
        )


class _Reader:
    """Reads little-endian fields off a payload; running out raises ValueError."""

    def __init__(self, data: bytes, version: tuple[int, int]) -> None:
        self.data = data
        self.offset = 0
        self.sizes = version >= (4, 1)

    def unpack(self, layout: struct.Struct) -> tuple[Any, ...]:
        if self.offset + layout.size > len(self.data):
            raise ValueError(f"a NatNet message cut short at byte {self.offset}")
        values = layout.unpack_from(self.data, self.offset)
        self.offset += layout.size
        return values

    def count(self, what: str) -> int:
        value = int(self.unpack(_INT)[0])
        if not 0 <= value <= MAX_COUNT:
            raise ValueError(f"a NatNet message with {value} {what}")
        return value

    def section(self, what: str) -> int:
        """A section's count, then (4.1+) its byte count, which is not needed."""
        value = self.count(what)
        if self.sizes:
            self.unpack(_INT)
        return value

    def skip(self, size: int) -> None:
        if self.offset + size > len(self.data):
            raise ValueError(f"a NatNet message cut short at byte {self.offset}")
        self.offset += size

    def string(self) -> str:
        end = self.data.find(b"\0", self.offset)
        if end < 0:
            raise ValueError(f"a NatNet name without its end at byte {self.offset}")
        text = self.data[self.offset : end].decode("utf-8", "replace")
        self.offset = end + 1
        return text


def parse_frame(payload: bytes, version: tuple[int, int]) -> tuple[int, list[RigidBody]]:
    """The frame number and rigid bodies of a NAT_FRAMEOFDATA payload.

    Raises:
        ValueError: not a frame of this NatNet version (the message says where).
    """
    check_version(version)
    reader = _Reader(payload, version)
    (frame,) = reader.unpack(_INT)
    for _ in range(reader.section("marker sets")):
        reader.string()
        reader.skip(12 * reader.count("markers"))
    reader.skip(12 * reader.section("unlabeled markers"))
    bodies = []
    for _ in range(reader.section("rigid bodies")):
        body_id, x, y, z, qx, qy, qz, qw, error, params = reader.unpack(_RIGID_BODY)
        bodies.append(RigidBody(body_id, (x, y, z), (qx, qy, qz, qw), error, bool(params & 1)))
    return frame, bodies


def parse_model_def(payload: bytes, version: tuple[int, int]) -> dict[int, str]:
    """``{id: name}`` of the rigid bodies a NAT_MODELDEF payload describes.

    Marker sets and skeletons are read past (a skeleton's bones are rigid bodies of their own
    ids, named too). Other kinds (force plates, devices, cameras) are skipped by their size in
    NatNet 4.1+; in 3.x and 4.0 the reading stops at the first one (Motive sends rigid bodies
    and skeletons before them).

    Raises:
        ValueError: a broken description (the message says where).
    """
    check_version(version)
    reader = _Reader(payload, version)
    names: dict[int, str] = {}
    for _ in range(reader.count("data sets")):
        (kind,) = reader.unpack(_INT)
        size = reader.unpack(_INT)[0] if reader.sizes else None
        if kind == MARKER_SET:
            reader.string()
            for _ in range(reader.count("markers")):
                reader.string()
        elif kind == RIGID_BODY:
            _rigid_body_description(reader, version, names)
        elif kind == SKELETON:
            reader.string()
            reader.unpack(_INT)
            for _ in range(reader.count("bones")):
                _rigid_body_description(reader, version, names)
        elif size is not None:
            reader.skip(size)
        else:
            break
    return names


def _rigid_body_description(
    reader: _Reader, version: tuple[int, int], names: dict[int, str]
) -> None:
    name = reader.string()
    body_id = reader.unpack(_DESCRIPTION_HEAD)[0]
    markers = reader.count("markers")
    reader.skip(16 * markers)
    if version[0] >= 4:
        for _ in range(markers):
            reader.string()
    names[body_id] = name
