"""Protocol 2.0: framing ``FF FF FD 00 ID LEN_L LEN_H INS P… CRC``, CRC-16, stuffing, the object."""

from __future__ import annotations

import logging
from collections.abc import Sequence

from poppy_core.errors import ProtocolError
from poppy_core.protocol.base import NEED_MORE, DxlProtocol, ErrorCodes, FrameReader
from poppy_core.protocol.constants import (
    BROADCAST_ID,
    FACTORY_RESET_OPTIONS,
    V2_HEADER,
    V2_MAX_LENGTH,
    Instruction,
)
from poppy_core.protocol.packets import InstructionPacket, StatusPacket

logger = logging.getLogger("poppy_core.protocol.decoder")

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


# e-manual (Protocol 2.0, Status Packet): bits 0-6 hold an error number, bit 7 is the alert flag.
V2_ERROR_NUMBERS: dict[int, str] = {
    1: "result fail",
    2: "instruction error",
    3: "CRC error",
    4: "data range error",
    5: "data length error",
    6: "data limit error",
    7: "access error",
}
V2_RESULT_FAIL = 0x01
V2_INSTRUCTION = 0x02
V2_CRC = 0x03
V2_DATA_RANGE = 0x04
V2_DATA_LENGTH = 0x05
V2_DATA_LIMIT = 0x06
V2_ACCESS = 0x07
V2_ALERT_BIT = 0x80
V2_ERROR_NUMBER_MASK = 0x7F

# Protocol 2: "Access Error: writing to a read-only or undefined address, or to EEPROM while
# Torque Enable is 1"; "Data Length Error: data shorter than the item"; "Data Limit Error:
# outside the limit value" (e-manual, Protocol 2.0 Status Packet).
V2_CODES = ErrorCodes(
    V2_INSTRUCTION, V2_CRC, V2_DATA_RANGE, V2_DATA_LENGTH, V2_DATA_LIMIT, V2_ACCESS, V2_ACCESS
)

# e-manual (Protocol 2.0, Packet / ID): usable IDs are 0-252 (0x00-0xFC); 0xFD is part of the
# header, 0xFE is broadcast.
V2_MAX_MOTOR_ID = 252

_STATUS = int(Instruction.STATUS)


class Protocol2(DxlProtocol):
    """Protocol 2.0 (XL-320, X series): two-byte fields, CRC-16, stuffing, error numbers."""

    version = 2
    header = V2_HEADER
    word_size = 2
    max_word = 0xFFFF
    instruction_overhead = 10  # FF FF FD 00 ID LEN_L LEN_H INS ... CRC_L CRC_H
    status_overhead = 11  # a status adds 0x55 then ERR
    ping_params = 3
    max_motor_id = V2_MAX_MOTOR_ID
    error_codes = V2_CODES
    status_fault_bits = None  # Hardware Error Status register; the status only has the alert bit
    sync_read_instruction = Instruction.SYNC_READ

    has_broadcast_ping = True
    has_sync_read = True
    usb2ax_sync_read = False
    has_fast_sync_read = True
    has_bulk_write = True
    has_reboot = True
    has_clear = True
    has_factory_reset_options = True

    # XL-320 and X-series firmware (e-manual: Torque Enable, Factory Reset, Data Length Error).
    torque_locks_eeprom = True
    whole_registers_only = True
    refuses_broadcast_reset_all = True

    def _alarm_only(self, error: int) -> bool:
        return error & V2_ERROR_NUMBER_MASK == 0

    def decode_errors(self, error: int) -> list[str]:
        names: list[str] = []
        number = error & V2_ERROR_NUMBER_MASK
        if number:
            names.append(V2_ERROR_NUMBERS.get(number, f"error {number}"))
        if error & V2_ALERT_BIT:
            names.append("hardware alert")
        return names

    def error_byte(self, code: int, fault_bits: int) -> int:
        return code | (V2_ALERT_BIT if fault_bits else 0)

    def _frame_instruction(self, packet: InstructionPacket) -> bytes:
        return encode_frame(packet.id, bytes((packet.instruction,)) + packet.params)

    def _frame_status(self, packet: StatusPacket) -> bytes:
        # A status from the broadcast ID only exists as the combined reply of a fast read, whose
        # layout is positional: it is sent without stuffing, like the Robotis SDK.
        body = bytes((Instruction.STATUS, packet.error)) + packet.params
        return encode_frame(packet.id, body, stuffing=packet.id != BROADCAST_ID)

    def read_frame(
        self, reader: FrameReader, pos: int, out: list[InstructionPacket | StatusPacket]
    ) -> int:
        # Packets of the other kind (the echo of our own instruction on a half-duplex bus,
        # recognised by INS being or not being 0x55) are dropped and counted as ignored.
        buf = reader._buf
        start = reader._skip_to_header(pos, V2_HEADER)
        if start == NEED_MORE:
            return NEED_MORE
        if len(buf) < start + 7:
            return reader._wait(start)
        packet_id = buf[start + 4]
        length = buf[start + 5] | (buf[start + 6] << 8)
        if packet_id == 0xFF:
            return reader._corrupt(start, "ID 0xFF")
        if length < 3 or length > V2_MAX_LENGTH:
            return reader._corrupt(start, f"LEN {length} out of 3..{V2_MAX_LENGTH}")
        end = start + 7 + length
        if _bad_stuffing(buf, start, end, packet_id):
            return reader._corrupt(start, "unstuffed FF FF FD inside the payload")
        if len(buf) < end:
            return reader._wait(start)
        crc = buf[end - 2] | (buf[end - 1] << 8)
        if crc16(memoryview(buf)[start : end - 2]) != crc:
            return reader._corrupt(start, "bad CRC")
        instruction = buf[start + 7]
        status = reader._status
        if (instruction == _STATUS) != status:
            reader.ignored_packets += 1
            return end
        # Stuffing covers INS and everything after it up to the CRC. A status from the broadcast
        # ID is a fast-read reply, positional and never stuffed (see _frame_status).
        region = bytes(buf[start + 7 : end - 2])
        if not (status and packet_id == BROADCAST_ID):
            region = unstuff(region)
        if not status:
            out.append(InstructionPacket(packet_id, instruction, region[1:]))
            return end
        if len(region) < 2:
            reader.corrupt_packets += 1
            logger.debug("protocol 2: status packet without an error byte dropped")
            return end
        out.append(StatusPacket(packet_id, region[1], region[2:]))
        return end

    def corrupt_frame_at(self, buf: bytearray, start: int) -> tuple[int, int] | None:
        if len(buf) < start + 8:
            return None
        length = buf[start + 5] | (buf[start + 6] << 8)
        end = start + 7 + length
        if length < 3 or len(buf) < end or buf[start + 4] == 0xFF:
            return None
        if crc16(buf[start : end - 2]) == buf[end - 2] | (buf[end - 1] << 8):
            return None
        return buf[start + 4], buf[start + 7]

    def ping_identity(self, params: bytes) -> tuple[int, int] | None:
        # e-manual (Protocol 2.0, Ping): model number (2 bytes, little-endian), firmware.
        return int.from_bytes(params[:2], "little"), params[2]

    def ping_reply(self, model_number: int, firmware: int) -> bytes:
        return model_number.to_bytes(2, "little") + bytes((firmware,))

    def factory_reset_params(self, option: int) -> bytes:
        if option not in FACTORY_RESET_OPTIONS:
            raise ProtocolError(f"factory reset option {option:#04x} is not 0xFF, 0x01 or 0x02")
        return bytes((option,))

    def parse_factory_reset(self, params: bytes) -> int:
        if len(params) != 1 or params[0] not in FACTORY_RESET_OPTIONS:
            raise ProtocolError(f"FACTORY_RESET option {params.hex(' ')!r} is not FF, 01 or 02")
        return params[0]

    def bulk_read_params(self, requests: Sequence[tuple[int, int, int]]) -> bytes:
        # e-manual (Protocol 2.0, Bulk Read): (ID ADDR_L ADDR_H LEN_L LEN_H) blocks.
        return b"".join(
            bytes((motor_id,)) + self.word(address, "address") + self.length_field(length)
            for motor_id, address, length in requests
        )

    def parse_bulk_read(self, params: bytes) -> list[tuple[int, int, int]]:
        if not params or len(params) % 5:
            raise ProtocolError(f"protocol 2 BULK_READ needs 5-byte blocks, got {len(params)}")
        return [
            (params[i], params[i + 1] | (params[i + 2] << 8), params[i + 3] | (params[i + 4] << 8))
            for i in range(0, len(params), 5)
        ]


def _bad_stuffing(buf: bytearray, start: int, end: int, packet_id: int) -> bool:
    """True when the payload seen so far holds an FF FF FD not followed by the stuffed FD.

    A genuine stuffed payload never does, so such a header is garbage (often a real header sits
    right there); rejecting it early avoids waiting for bytes of a length that was never sent.
    Fast-read replies (status from the broadcast ID) are not stuffed: skipped.
    """
    region_end = min(end - 2, len(buf))
    first = start + 7
    if packet_id == BROADCAST_ID and (first >= len(buf) or buf[first] == _STATUS):
        return False
    idx = buf.find(_PATTERN, first, region_end)
    while idx >= 0:
        if idx + 3 < region_end and buf[idx + 3] != 0xFD:
            return True
        idx = buf.find(_PATTERN, idx + 4, region_end)
    return False


PROTOCOL_2 = Protocol2()
