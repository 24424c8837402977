"""The combined status packet that answers a protocol 2 FAST_SYNC_READ.

e-manual (Protocol 2.0, Fast Sync Read): the devices answer together with one status packet from
the broadcast ID::

    FF FF FD 00 FE LEN_L LEN_H 55  ERR1 ID1 DATA1 CRC1  ERR2 ID2 DATA2 CRC2 … ERRn IDn DATAn CRC

with LEN = 1 + n * (L + 4). Each device appends its block and ends it with the CRC of the whole
packet so far (from the first header byte), so the last block's CRC is the usual packet CRC. The
reply is positional and sent without byte stuffing (the Robotis SDK reads it without
unstuffing). ``PacketDecoder`` returns it as ``StatusPacket(0xFE, ERR1, ID1 DATA1 CRC1 … DATAn)``.
"""

from __future__ import annotations

from collections.abc import Sequence

from poppy_core.errors import ProtocolError
from poppy_core.protocol.constants import (
    BROADCAST_ID,
    MAX_ID,
    V2_HEADER,
    V2_MAX_LENGTH,
    Instruction,
)
from poppy_core.protocol.packets import StatusPacket
from poppy_core.protocol.v2 import crc16


def encode_fast_sync_status(replies: Sequence[tuple[int, int, bytes]]) -> bytes:
    """Bytes of the combined fast sync read reply.

    Args:
        replies: ``(id, error, data)`` per answering device, in request order.

    Returns:
        The complete packet bytes.

    Raises:
        ProtocolError: no reply, a bad ID or error byte, or a packet too long.
    """
    if not replies:
        raise ProtocolError("a fast sync read reply needs at least one device")
    length = 1 + sum(4 + len(data) for _, _, data in replies)
    if length > V2_MAX_LENGTH:
        raise ProtocolError(f"fast sync read reply length {length} exceeds {V2_MAX_LENGTH}")
    out = bytearray(V2_HEADER)
    out += bytes((BROADCAST_ID, length & 0xFF, length >> 8, Instruction.STATUS))
    crc = crc16(out)
    for motor_id, error, data in replies:
        if not 0 <= motor_id <= MAX_ID or not 0 <= error <= 0xFF:
            raise ProtocolError(f"bad fast sync read block: ID {motor_id}, error {error}")
        block = bytes((error, motor_id)) + bytes(data)
        crc = crc16(block, crc)
        out += block
        out += bytes((crc & 0xFF, crc >> 8))
        crc = crc16(out[-2:], crc)
    return bytes(out)


def parse_fast_sync_status(packet: StatusPacket, length: int) -> dict[int, tuple[int, bytes]]:
    """Split a decoded fast sync read reply into ``{id: (error, data)}``.

    The intermediate CRCs are not checked: the packet CRC already covers every byte.

    Args:
        packet: the status packet returned by ``PacketDecoder`` (ID 0xFE).
        length: the data length asked for in the FAST_SYNC_READ.

    Raises:
        ProtocolError: not from the broadcast ID, or a size that is not n blocks of
            ``length + 4`` bytes, or a duplicate ID.
    """
    if packet.id != BROADCAST_ID:
        raise ProtocolError(f"fast sync read reply from ID {packet.id}, expected {BROADCAST_ID}")
    if length < 1:
        raise ProtocolError(f"data length {length} must be at least 1")
    block = length + 4
    # Re-attach ERR1 in front and a placeholder for the packet CRC the decoder removed.
    blob = bytes((packet.error,)) + packet.params + b"\x00\x00"
    if len(blob) % block:
        raise ProtocolError(
            f"fast sync read reply of {len(blob)} bytes is not whole blocks of {block}"
        )
    result: dict[int, tuple[int, bytes]] = {}
    for start in range(0, len(blob), block):
        motor_id = blob[start + 1]
        if motor_id in result:
            raise ProtocolError(f"fast sync read reply holds ID {motor_id} twice")
        result[motor_id] = (blob[start], blob[start + 2 : start + 2 + length])
    return result
