"""Turn packets into bytes for protocol 1 or 2 (``encode_instruction``, ``encode_status``)."""

from __future__ import annotations

from poppy_core.errors import ProtocolError
from poppy_core.protocol import v1, v2
from poppy_core.protocol.constants import BROADCAST_ID, MAX_ID, PROTOCOLS, Instruction
from poppy_core.protocol.packets import InstructionPacket, StatusPacket


def check_protocol(protocol: int) -> None:
    """Raise ``ProtocolError`` unless ``protocol`` is 1 or 2."""
    if protocol not in PROTOCOLS:
        raise ProtocolError(f"unknown Dynamixel protocol {protocol!r} (expected 1 or 2)")


def _check_id(packet_id: int) -> None:
    if not (0 <= packet_id <= MAX_ID or packet_id == BROADCAST_ID):
        raise ProtocolError(
            f"ID {packet_id} cannot be encoded (0..{MAX_ID} or broadcast {BROADCAST_ID})"
        )


def encode_instruction(protocol: int, packet: InstructionPacket) -> bytes:
    """Encode an instruction packet.

    Args:
        protocol: 1 or 2.
        packet: the packet; its params are raw (stuffing is applied here for protocol 2).

    Returns:
        The bytes to put on the wire.

    Raises:
        ProtocolError: bad protocol, ID, instruction byte or too many parameters.
    """
    check_protocol(protocol)
    _check_id(packet.id)
    if not 0 <= packet.instruction <= 0xFF:
        raise ProtocolError(f"instruction {packet.instruction} is not a byte")
    if protocol == 1:
        return v1.encode_frame(packet.id, packet.instruction, packet.params)
    return v2.encode_frame(packet.id, bytes((packet.instruction,)) + packet.params)


def encode_status(protocol: int, packet: StatusPacket) -> bytes:
    """Encode a status packet.

    Protocol 2 status packets carry ``INS=0x55`` then the error byte. A status from the broadcast
    ID only exists as the combined reply of a fast read, whose layout is positional: it is sent
    without byte stuffing (and ``PacketDecoder`` does not unstuff it), like the Robotis SDK.

    Args:
        protocol: 1 or 2.
        packet: the packet; its params are raw.

    Returns:
        The bytes to put on the wire.

    Raises:
        ProtocolError: bad protocol, ID, error byte or too many parameters.
    """
    check_protocol(protocol)
    _check_id(packet.id)
    if not 0 <= packet.error <= 0xFF:
        raise ProtocolError(f"error byte {packet.error} is not a byte")
    if protocol == 1:
        return v1.encode_frame(packet.id, packet.error, packet.params)
    body = bytes((Instruction.STATUS, packet.error)) + packet.params
    return v2.encode_frame(packet.id, body, stuffing=packet.id != BROADCAST_ID)
