"""``DxlProtocol``: what one Dynamixel protocol is (sizes, error layout, codec, capabilities).

One object per protocol (``PROTOCOL_1`` in ``v1``, ``PROTOCOL_2`` in ``v2``; ``protocol_for``
in ``versions`` looks one up), as the Dynamixel SDK has one packet handler per protocol. Code
above asks the object (``proto.has_broadcast_ping``, ``proto.encode_instruction(packet)``)
instead of comparing protocol numbers; only the subclasses know which protocol they are.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import ClassVar, Protocol

from poppy_core.errors import ProtocolError
from poppy_core.protocol.constants import BROADCAST_ID, MAX_ID, Instruction
from poppy_core.protocol.packets import InstructionPacket, StatusPacket

#: ``read_frame`` result: the decoder must wait for more bytes.
NEED_MORE = -1


@dataclass(frozen=True)
class ErrorCodes:
    """The status error byte a protocol uses for each kind of refused instruction."""

    instruction: int
    checksum: int
    range: int
    length: int
    limit: int
    access: int
    eeprom_locked: int


class FrameReader(Protocol):
    """The state of a streaming decoder that a protocol's framing reads (``PacketDecoder``)."""

    _buf: bytearray
    _status: bool
    corrupt_packets: int
    skipped_bytes: int
    ignored_packets: int

    def _skip_to_header(self, pos: int, header: bytes) -> int: ...

    def _corrupt(self, start: int, reason: str) -> int: ...

    def _wait(self, keep_from: int) -> int: ...


def check_id(packet_id: int) -> None:
    """Raise ``ProtocolError`` unless ``packet_id`` is a motor ID or the broadcast ID."""
    if not (0 <= packet_id <= MAX_ID or packet_id == BROADCAST_ID):
        raise ProtocolError(
            f"ID {packet_id} cannot be encoded (0..{MAX_ID} or broadcast {BROADCAST_ID})"
        )


def check_ids(raw: bytes, what: str) -> list[int]:
    """The motor IDs of a parsed instruction; out-of-range or duplicate IDs raise."""
    ids = list(raw)
    for motor_id in ids:
        if motor_id > MAX_ID:
            raise ProtocolError(f"{what}: motor ID {motor_id} is not in 0..{MAX_ID}")
    if len(set(ids)) != len(ids):
        raise ProtocolError(f"{what}: duplicate motor IDs in {ids}")
    return ids


class DxlProtocol(ABC):
    """One Dynamixel protocol. Pure: no I/O, no state; the two instances are shared.

    Attributes (sizes and layout):
        version: 1 or 2 (the number users write in configs).
        header: the bytes every packet starts with.
        word_size / max_word: bytes and largest value of an address or length field.
        instruction_overhead / status_overhead: packet bytes besides the parameters.
        ping_params: parameter bytes of a ping's status packet.
        max_motor_id: the largest ID a motor may take.
        error_codes: the status error byte for each kind of refused instruction.
        status_fault_bits: hardware errors the status error byte names bit by bit, or None
            when they live in a Hardware Error Status register (only an alert bit in status).

    Attributes (capabilities):
        has_broadcast_ping: every motor answers a PING to the broadcast ID.
        has_sync_read: the SYNC_READ instruction exists (protocol 1 has only the USB2AX's).
        usb2ax_sync_read: sync read is the USB2AX adapter's extension (0x84, one reply
            from ID 0xFD); the adapter also answers a ping of its own ID.
        has_fast_sync_read / has_bulk_write / has_reboot / has_clear: those instructions exist.
        has_factory_reset_options: FACTORY_RESET takes an option (keep ID, keep baud rate).

    Attributes (firmware rules shared by every servo speaking the protocol):
        torque_locks_eeprom: EEPROM writes are refused while the torque is on.
        whole_registers_only: a write covering part of a register is refused.
        refuses_broadcast_reset_all: a broadcast "reset all" FACTORY_RESET is not executed.
    """

    version: ClassVar[int]
    header: ClassVar[bytes]
    word_size: ClassVar[int]
    max_word: ClassVar[int]
    instruction_overhead: ClassVar[int]
    status_overhead: ClassVar[int]
    ping_params: ClassVar[int]
    max_motor_id: ClassVar[int]
    error_codes: ClassVar[ErrorCodes]
    status_fault_bits: ClassVar[Mapping[str, int] | None]
    sync_read_instruction: ClassVar[Instruction]

    has_broadcast_ping: ClassVar[bool]
    has_sync_read: ClassVar[bool]
    usb2ax_sync_read: ClassVar[bool]
    has_fast_sync_read: ClassVar[bool]
    has_bulk_write: ClassVar[bool]
    has_reboot: ClassVar[bool]
    has_clear: ClassVar[bool]
    has_factory_reset_options: ClassVar[bool]

    torque_locks_eeprom: ClassVar[bool]
    whole_registers_only: ClassVar[bool]
    refuses_broadcast_reset_all: ClassVar[bool]

    def __repr__(self) -> str:
        return f"<Dynamixel protocol {self.version}>"

    # ------------------------------------------------------------------ sizes

    def instruction_size(self, n_params: int) -> int:
        """Bytes of an instruction packet carrying ``n_params`` parameter bytes (unstuffed)."""
        return self.instruction_overhead + n_params

    def status_size(self, n_params: int) -> int:
        """Bytes of a status packet carrying ``n_params`` parameter bytes (unstuffed)."""
        return self.status_overhead + n_params

    def word(self, value: int, what: str) -> bytes:
        """An address or length field (little-endian, ``word_size`` bytes)."""
        limit = self.max_word
        if not 0 <= value <= limit:
            raise ProtocolError(f"{what} {value} is not in 0..{limit} for protocol {self.version}")
        return value.to_bytes(self.word_size, "little")

    def length_field(self, length: int) -> bytes:
        """A data length field (at least 1)."""
        if length < 1:
            raise ProtocolError(f"data length {length} must be at least 1")
        return self.word(length, "data length")

    # ------------------------------------------------------------------ status error byte

    def is_alarm_only(self, error: int) -> bool:
        """True when ``error`` carries only alarm bits (the instruction was still executed)."""
        return error != 0 and self._alarm_only(error)

    @abstractmethod
    def _alarm_only(self, error: int) -> bool: ...

    @abstractmethod
    def decode_errors(self, error: int) -> list[str]:
        """Readable names of the errors flagged in a status packet's error byte."""

    @abstractmethod
    def error_byte(self, code: int, fault_bits: int) -> int:
        """A device's status error byte: instruction result ``code`` plus its hardware faults."""

    # ------------------------------------------------------------------ codec

    def encode_instruction(self, packet: InstructionPacket) -> bytes:
        """Bytes of an instruction packet (params raw; stuffing applied where the protocol has it).

        Raises:
            ProtocolError: bad ID, instruction byte or too many parameters.
        """
        check_id(packet.id)
        if not 0 <= packet.instruction <= 0xFF:
            raise ProtocolError(f"instruction {packet.instruction} is not a byte")
        return self._frame_instruction(packet)

    def encode_status(self, packet: StatusPacket) -> bytes:
        """Bytes of a status packet (params raw).

        Raises:
            ProtocolError: bad ID, error byte or too many parameters.
        """
        check_id(packet.id)
        if not 0 <= packet.error <= 0xFF:
            raise ProtocolError(f"error byte {packet.error} is not a byte")
        return self._frame_status(packet)

    @abstractmethod
    def _frame_instruction(self, packet: InstructionPacket) -> bytes: ...

    @abstractmethod
    def _frame_status(self, packet: StatusPacket) -> bytes: ...

    @abstractmethod
    def read_frame(
        self, reader: FrameReader, pos: int, out: list[InstructionPacket | StatusPacket]
    ) -> int:
        """Decode the next packet of ``reader``'s buffer from ``pos`` (``PacketDecoder``'s step).

        Returns:
            Where the search continues, or ``NEED_MORE``.
        """

    @abstractmethod
    def corrupt_frame_at(self, buf: bytearray, start: int) -> tuple[int, int] | None:
        """``(id, instruction)`` when a complete frame at ``start`` fails its check."""

    # ------------------------------------------------------------------ instructions

    @abstractmethod
    def ping_identity(self, params: bytes) -> tuple[int, int] | None:
        """``(model number, firmware)`` carried by a ping's status, None when a ping has none."""

    @abstractmethod
    def ping_reply(self, model_number: int, firmware: int) -> bytes:
        """The parameters of a device's answer to a ping."""

    @abstractmethod
    def factory_reset_params(self, option: int) -> bytes:
        """Parameters of a FACTORY_RESET with ``option`` (0xFF, 0x01 or 0x02)."""

    @abstractmethod
    def parse_factory_reset(self, params: bytes) -> int:
        """Option of a FACTORY_RESET (0xFF, reset everything, when the protocol has none)."""

    @abstractmethod
    def bulk_read_params(self, requests: Sequence[tuple[int, int, int]]) -> bytes:
        """Parameters of a BULK_READ of ``(id, address, length)`` requests."""

    @abstractmethod
    def parse_bulk_read(self, params: bytes) -> list[tuple[int, int, int]]:
        """``[(id, address, length)]`` of a BULK_READ."""
