"""Protocol 1.0 framing: ``FF FF ID LEN INS/ERR P… CHK`` and its checksum."""

from __future__ import annotations

from poppy_core.errors import ProtocolError
from poppy_core.protocol.constants import V1_HEADER, V1_MAX_PARAMS


def checksum(body: bytes | bytearray | memoryview) -> int:
    """Protocol 1 checksum of the bytes from ID through the last parameter.

    e-manual (Protocol 1.0, Instruction Packet): ``~(ID + LEN + INS + P1 + … + PN) & 0xFF``.

    Args:
        body: the bytes ``ID LEN INS/ERR P…`` (header and checksum excluded).

    Returns:
        The checksum byte.
    """
    return ~sum(body) & 0xFF


def encode_frame(packet_id: int, code: int, params: bytes) -> bytes:
    """Frame one protocol 1 packet (instruction or status: ``code`` is INS or ERR).

    Args:
        packet_id: the ID byte (already validated by the caller).
        code: the instruction or error byte.
        params: raw parameters.

    Returns:
        The complete packet bytes.

    Raises:
        ProtocolError: too many parameters for the one-byte LEN, or a byte out of range.
    """
    if len(params) > V1_MAX_PARAMS:
        raise ProtocolError(
            f"protocol 1 packet cannot carry {len(params)} parameter bytes (max {V1_MAX_PARAMS})"
        )
    if not 0 <= code <= 0xFF:
        raise ProtocolError(f"instruction/error byte {code} is not in 0..255")
    body = bytes((packet_id, len(params) + 2, code)) + params
    return V1_HEADER + body + bytes((checksum(body),))
