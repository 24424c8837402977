"""Protocol 2.0 framing (``FF FF FD 00 ID LEN_L LEN_H INS P… CRC_L CRC_H``), CRC-16, stuffing."""

from __future__ import annotations

from poppy_core.errors import ProtocolError
from poppy_core.protocol.constants import V2_HEADER, V2_MAX_LENGTH

# e-manual (Protocol 2.0, CRC): CRC-16 with polynomial 0x8005 (x^16 + x^15 + x^2 + 1), initial
# value 0, no reflection, no final xor; computed over the whole packet from the header up to (not
# including) the CRC, after byte stuffing. The 256-entry table is derived here from the polynomial.
_POLY = 0x8005


def _make_table() -> tuple[int, ...]:
    table = []
    for byte in range(256):
        crc = byte << 8
        for _ in range(8):
            crc = ((crc << 1) ^ _POLY) if crc & 0x8000 else (crc << 1)
        table.append(crc & 0xFFFF)
    return tuple(table)


CRC_TABLE = _make_table()

# e-manual (Protocol 2.0, Byte Stuffing): inside the instruction/parameter field, every FF FF FD
# is followed by an extra FD; LEN counts the stuffed bytes. The pattern cannot overlap itself, so
# a plain replace is exact in both directions.
_PATTERN = b"\xff\xff\xfd"
_STUFFED = b"\xff\xff\xfd\xfd"


def crc16(data: bytes | bytearray | memoryview, crc: int = 0) -> int:
    """CRC-16 of protocol 2.

    Args:
        data: the bytes to cover.
        crc: a running value to continue from (0 to start).

    Returns:
        The 16-bit CRC.
    """
    table = CRC_TABLE
    for byte in data:
        crc = ((crc << 8) ^ table[((crc >> 8) ^ byte) & 0xFF]) & 0xFFFF
    return crc


def stuff(region: bytes) -> bytes:
    """Apply byte stuffing to the INS + parameters field (insert FD after each FF FF FD)."""
    if _PATTERN not in region:
        return region
    return region.replace(_PATTERN, _STUFFED)


def unstuff(region: bytes) -> bytes:
    """Undo byte stuffing (drop the FD that follows each FF FF FD)."""
    if _STUFFED not in region:
        return region
    return region.replace(_STUFFED, _PATTERN)


def encode_frame(packet_id: int, body: bytes, *, stuffing: bool = True) -> bytes:
    """Frame one protocol 2 packet around ``body`` (``INS P…`` or ``55 ERR P…``).

    Args:
        packet_id: the ID byte (already validated by the caller).
        body: instruction byte (and error byte for a status) followed by raw parameters.
        stuffing: apply byte stuffing (off only for the positional fast-read replies).

    Returns:
        The complete packet bytes, CRC included.

    Raises:
        ProtocolError: the packet would be longer than ``V2_MAX_LENGTH``.
    """
    if stuffing:
        body = stuff(body)
    length = len(body) + 2
    if length > V2_MAX_LENGTH:
        raise ProtocolError(
            f"protocol 2 packet length {length} exceeds the limit of {V2_MAX_LENGTH}"
        )
    frame = V2_HEADER + bytes((packet_id, length & 0xFF, length >> 8)) + body
    crc = crc16(frame)
    return frame + bytes((crc & 0xFF, crc >> 8))
