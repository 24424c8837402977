"""Protocol 1.0: framing ``FF FF ID LEN INS/ERR P… CHK``, checksum, error bits, ``PROTOCOL_1``."""

from __future__ import annotations

from collections.abc import Sequence
from types import MappingProxyType

from poppy_core.errors import ProtocolError
from poppy_core.protocol.base import NEED_MORE, DxlProtocol, ErrorCodes, FrameReader
from poppy_core.protocol.constants import (
    FACTORY_RESET_ALL,
    MAX_ID,
    V1_HEADER,
    V1_MAX_PARAMS,
    Instruction,
)
from poppy_core.protocol.packets import InstructionPacket, StatusPacket


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


# e-manual (Protocol 1.0, Status Packet): one flag per bit, bit 7 unused.
V1_ERROR_BITS: tuple[str, ...] = (
    "input voltage",
    "angle limit",
    "overheating",
    "range",
    "checksum",
    "overload",
    "instruction",
)
V1_INPUT_VOLTAGE = 0x01
V1_ANGLE_LIMIT = 0x02
V1_OVERHEATING = 0x04
V1_RANGE = 0x08
V1_CHECKSUM = 0x10
V1_OVERLOAD = 0x20
V1_INSTRUCTION = 0x40
#: Alarm bits: input voltage, overheating, overload (the instruction was still executed).
V1_ALARM_MASK = V1_INPUT_VOLTAGE | V1_OVERHEATING | V1_OVERLOAD

# Protocol 1 has no access/length error: a write to a read-only address or past the table is
# "out of the defined range" (Range Error); a goal position outside the CW/CCW limits sets the
# Angle Limit Error bit (e-manual, Protocol 1.0 Status Packet).
V1_CODES = ErrorCodes(V1_INSTRUCTION, V1_CHECKSUM, V1_RANGE, V1_RANGE, V1_ANGLE_LIMIT, V1_RANGE, 0)


class Protocol1(DxlProtocol):
    """Protocol 1.0 (AX, MX, RX servos): one-byte fields, a checksum, flags in the error byte."""

    version = 1
    header = V1_HEADER
    word_size = 1
    max_word = 0xFF
    instruction_overhead = 6  # FF FF ID LEN INS/ERR ... CHK
    status_overhead = 6
    ping_params = 0
    max_motor_id = MAX_ID
    error_codes = V1_CODES
    status_fault_bits = MappingProxyType({name: 1 << bit for bit, name in enumerate(V1_ERROR_BITS)})
    sync_read_instruction = Instruction.SYNC_READ_USB2AX

    has_broadcast_ping = False
    has_sync_read = False
    usb2ax_sync_read = True
    has_fast_sync_read = False
    has_bulk_write = False
    has_reboot = False
    has_clear = False
    has_factory_reset_options = False

    # AX/MX firmware accepts EEPROM writes with the torque on and partial register writes.
    torque_locks_eeprom = False
    whole_registers_only = False
    refuses_broadcast_reset_all = False

    def _alarm_only(self, error: int) -> bool:
        return error & ~V1_ALARM_MASK & 0xFF == 0

    def decode_errors(self, error: int) -> list[str]:
        return [name for bit, name in enumerate(V1_ERROR_BITS) if error & (1 << bit)]

    def error_byte(self, code: int, fault_bits: int) -> int:
        return code | fault_bits

    def _frame_instruction(self, packet: InstructionPacket) -> bytes:
        return encode_frame(packet.id, packet.instruction, packet.params)

    def _frame_status(self, packet: StatusPacket) -> bytes:
        return encode_frame(packet.id, packet.error, packet.params)

    def read_frame(
        self, reader: FrameReader, pos: int, out: list[InstructionPacket | StatusPacket]
    ) -> int:
        # The kind alone decides whether the byte after LEN is an instruction or an error.
        buf = reader._buf
        start = reader._skip_to_header(pos, V1_HEADER)
        if start == NEED_MORE:
            return NEED_MORE
        if len(buf) < start + 4:
            return reader._wait(start)
        packet_id = buf[start + 2]
        if packet_id == 0xFF:
            # FF FF FF: the real header starts one byte later.
            reader.skipped_bytes += 1
            return start + 1
        length = buf[start + 3]
        if length < 2:
            return reader._corrupt(start, f"LEN {length} < 2")
        end = start + 4 + length
        if len(buf) < end:
            return reader._wait(start)
        if ~sum(buf[start + 2 : end - 1]) & 0xFF != buf[end - 1]:
            return reader._corrupt(start, "bad checksum")
        code = buf[start + 4]
        params = bytes(buf[start + 5 : end - 1])
        if reader._status:
            out.append(StatusPacket(packet_id, code, params))
        else:
            out.append(InstructionPacket(packet_id, code, params))
        return end

    def corrupt_frame_at(self, buf: bytearray, start: int) -> tuple[int, int] | None:
        if len(buf) < start + 5 or buf[start + 2] == 0xFF:
            return None
        end = start + 4 + buf[start + 3]
        if buf[start + 3] < 2 or len(buf) < end:
            return None
        if checksum(buf[start + 2 : end - 1]) == buf[end - 1]:
            return None
        return buf[start + 2], buf[start + 4]

    def ping_identity(self, params: bytes) -> tuple[int, int] | None:
        return None  # protocol 1 pings carry no model number: it is read from the table

    def ping_reply(self, model_number: int, firmware: int) -> bytes:
        return b""

    def factory_reset_params(self, option: int) -> bytes:
        if option != FACTORY_RESET_ALL:
            raise ProtocolError("protocol 1 factory reset has no option (it resets everything)")
        return b""

    def parse_factory_reset(self, params: bytes) -> int:
        if params:
            raise ProtocolError("protocol 1 FACTORY_RESET takes no parameter")
        return FACTORY_RESET_ALL

    def bulk_read_params(self, requests: Sequence[tuple[int, int, int]]) -> bytes:
        # e-manual (MX, Bulk Read): 00 then (LEN ID ADDR) blocks.
        parts = [b"\x00"]
        for motor_id, address, length in requests:
            addr, size = self.word(address, "address"), self.length_field(length)
            parts.append(size + bytes((motor_id,)) + addr)
        return b"".join(parts)

    def parse_bulk_read(self, params: bytes) -> list[tuple[int, int, int]]:
        if not params or params[0] != 0x00 or len(params) < 4 or (len(params) - 1) % 3:
            raise ProtocolError(
                f"protocol 1 BULK_READ needs 00 then (LEN ID ADDR) blocks, got {params.hex(' ')}"
            )
        return [(params[i + 1], params[i + 2], params[i]) for i in range(1, len(params), 3)]


PROTOCOL_1 = Protocol1()
