"""Turn packets into bytes for protocol 1 or 2 (``encode_instruction``, ``encode_status``).

Thin functions over the protocol objects (``protocol_for(n).encode_instruction``) for callers
that hold a version number.
"""

from __future__ import annotations

from poppy_core.protocol.base import DxlProtocol
from poppy_core.protocol.packets import InstructionPacket, StatusPacket
from poppy_core.protocol.versions import protocol_for


def check_protocol(protocol: int | DxlProtocol) -> None:
    """Raise ``ProtocolError`` unless ``protocol`` is 1 or 2."""
    protocol_for(protocol)


def encode_instruction(protocol: int | DxlProtocol, packet: InstructionPacket) -> bytes:
    """Encode an instruction packet.

    Args:
        protocol: 1 or 2 (or its protocol object).
        packet: the packet; its params are raw (stuffing is applied here for protocol 2).

    Returns:
        The bytes to put on the wire.

    Raises:
        ProtocolError: bad protocol, ID, instruction byte or too many parameters.
    """
    return protocol_for(protocol).encode_instruction(packet)


def encode_status(protocol: int | DxlProtocol, packet: StatusPacket) -> bytes:
    """Encode a status packet.

    Protocol 2 status packets carry ``INS=0x55`` then the error byte. A status from the broadcast
    ID only exists as the combined reply of a fast read, whose layout is positional: it is sent
    without byte stuffing (and ``PacketDecoder`` does not unstuff it), like the Robotis SDK.

    Args:
        protocol: 1 or 2 (or its protocol object).
        packet: the packet; its params are raw.

    Returns:
        The bytes to put on the wire.

    Raises:
        ProtocolError: bad protocol, ID, error byte or too many parameters.
    """
    return protocol_for(protocol).encode_status(packet)
