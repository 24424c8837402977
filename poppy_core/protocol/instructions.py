"""Builders of every instruction packet, and parsers of their parameters (for the emulator).

Layouts (e-manual, Protocol 1.0 and 2.0 "Instruction Details"; addresses and lengths are one
byte in protocol 1, two little-endian bytes in protocol 2):

- READ: ``ADDR LEN``. WRITE / REG_WRITE: ``ADDR DATA…``.
- FACTORY_RESET: no parameter in protocol 1; protocol 2 adds the option byte (0xFF all,
  0x01 all but ID, 0x02 all but ID and baud rate).
- CLEAR (protocol 2): ``01 44 58 4C 22`` clears the multi-turn revolution count.
- SYNC_READ / FAST_SYNC_READ (protocol 2, to the broadcast ID): ``ADDR LEN ID1 ID2 …``.
- SYNC_WRITE (broadcast): ``ADDR LEN (ID DATA[LEN])…``.
- BULK_READ: protocol 1 ``00 (LEN ID ADDR)…``; protocol 2 ``(ID ADDR LEN)…``.
- BULK_WRITE (protocol 2): ``(ID ADDR LEN DATA[LEN])…``.

Protocol 1 sync read is the USB2AX extension 0x84 (USB2AX firmware, advanced_commands.txt). The
host sends ``FF FF FE LEN 84 ADDR L ID1 ID2 … CHK`` (the adapter also accepts ID 0xFD); the
adapter reads each motor itself and answers with ONE status packet from ID 0xFD::

    FF FF FD LEN ERR DATA(ID1)[L] DATA(ID2)[L] … CHK    with LEN = L * N + 2

i.e. all motors' data concatenated in request order. A motor that did not answer is filled
with ``L`` bytes 0xFF; ERR only reports a bad L or N (range error). ``usb2ax_sync_status`` and
``parse_usb2ax_sync_status`` build and split that packet.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence

from poppy_core.errors import ProtocolError
from poppy_core.protocol.base import DxlProtocol
from poppy_core.protocol.constants import (
    BROADCAST_ID,
    CLEAR_KEY,
    CLEAR_MULTI_TURN,
    FACTORY_RESET_ALL,
    MAX_ID,
    USB2AX_ID,
    Instruction,
)
from poppy_core.protocol.packets import InstructionPacket, StatusPacket
from poppy_core.protocol.v2 import PROTOCOL_2
from poppy_core.protocol.versions import protocol_for


def _check_target(packet_id: int) -> None:
    if not (0 <= packet_id <= MAX_ID or packet_id == BROADCAST_ID):
        raise ProtocolError(f"ID {packet_id} is not 0..{MAX_ID} or broadcast {BROADCAST_ID}")


def _check_motor_ids(ids: Iterable[int]) -> list[int]:
    id_list = list(ids)
    if not id_list:
        raise ProtocolError("at least one motor ID is needed")
    for motor_id in id_list:
        if not 0 <= motor_id <= MAX_ID:
            raise ProtocolError(f"motor ID {motor_id} is not in 0..{MAX_ID}")
    if len(set(id_list)) != len(id_list):
        raise ProtocolError(f"duplicate motor IDs in {id_list}")
    return id_list


Proto = int | DxlProtocol


# ---------------------------------------------------------------- builders


def ping(id: int) -> InstructionPacket:
    """PING ``id`` (both protocols)."""
    _check_target(id)
    return InstructionPacket(id, Instruction.PING)


def read(protocol: Proto, id: int, address: int, length: int) -> InstructionPacket:
    """READ ``length`` bytes from ``address`` of motor ``id``."""
    proto = protocol_for(protocol)
    _check_target(id)
    params = proto.word(address, "address") + proto.length_field(length)
    return InstructionPacket(id, Instruction.READ, params)


def write(protocol: Proto, id: int, address: int, data: bytes) -> InstructionPacket:
    """WRITE ``data`` at ``address`` of motor ``id``."""
    return _write(protocol, Instruction.WRITE, id, address, data)


def reg_write(protocol: Proto, id: int, address: int, data: bytes) -> InstructionPacket:
    """REG_WRITE ``data`` at ``address``: held by the motor until ACTION."""
    return _write(protocol, Instruction.REG_WRITE, id, address, data)


def _write(
    protocol: Proto, instruction: Instruction, id: int, address: int, data: bytes
) -> InstructionPacket:
    proto = protocol_for(protocol)
    _check_target(id)
    if not data:
        raise ProtocolError("a write needs at least one data byte")
    return InstructionPacket(id, instruction, proto.word(address, "address") + bytes(data))


def action(id: int = BROADCAST_ID) -> InstructionPacket:
    """ACTION: run the registered REG_WRITE (broadcast by default)."""
    _check_target(id)
    return InstructionPacket(id, Instruction.ACTION)


def factory_reset(protocol: Proto, id: int, option: int = FACTORY_RESET_ALL) -> InstructionPacket:
    """FACTORY_RESET motor ``id``; protocol 2 sends ``option`` (0xFF, 0x01 or 0x02)."""
    proto = protocol_for(protocol)
    _check_target(id)
    return InstructionPacket(id, Instruction.FACTORY_RESET, proto.factory_reset_params(option))


def reboot(id: int) -> InstructionPacket:
    """REBOOT motor ``id``."""
    _check_target(id)
    return InstructionPacket(id, Instruction.REBOOT)


def clear(id: int) -> InstructionPacket:
    """CLEAR the multi-turn revolution count of motor ``id`` (protocol 2)."""
    _check_target(id)
    return InstructionPacket(id, Instruction.CLEAR, bytes((CLEAR_MULTI_TURN,)) + CLEAR_KEY)


def sync_read(protocol: Proto, address: int, length: int, ids: Iterable[int]) -> InstructionPacket:
    """SYNC_READ (protocol 2, 0x82) or the USB2AX sync read (protocol 1, 0x84)."""
    proto = protocol_for(protocol)
    id_list = _check_motor_ids(ids)
    params = proto.word(address, "address") + proto.length_field(length) + bytes(id_list)
    return InstructionPacket(BROADCAST_ID, proto.sync_read_instruction, params)


def fast_sync_read(address: int, length: int, ids: Iterable[int]) -> InstructionPacket:
    """FAST_SYNC_READ (protocol 2, 0x8A): one combined reply (see ``parse_fast_sync_status``)."""
    id_list = _check_motor_ids(ids)
    params = PROTOCOL_2.word(address, "address") + PROTOCOL_2.length_field(length) + bytes(id_list)
    return InstructionPacket(BROADCAST_ID, Instruction.FAST_SYNC_READ, params)


def sync_write(
    protocol: Proto, address: int, length: int, data: Mapping[int, bytes]
) -> InstructionPacket:
    """SYNC_WRITE ``length`` bytes at ``address`` of several motors: ``data`` maps ID -> bytes."""
    proto = protocol_for(protocol)
    _check_motor_ids(data)
    parts = [proto.word(address, "address"), proto.length_field(length)]
    for motor_id, chunk in data.items():
        if len(chunk) != length:
            raise ProtocolError(
                f"sync write data for ID {motor_id} has {len(chunk)} bytes, expected {length}"
            )
        parts.append(bytes((motor_id,)))
        parts.append(bytes(chunk))
    return InstructionPacket(BROADCAST_ID, Instruction.SYNC_WRITE, b"".join(parts))


def bulk_read(protocol: Proto, requests: Sequence[tuple[int, int, int]]) -> InstructionPacket:
    """BULK_READ: ``requests`` is a sequence of ``(id, address, length)``."""
    proto = protocol_for(protocol)
    _check_motor_ids(r[0] for r in requests)
    return InstructionPacket(BROADCAST_ID, Instruction.BULK_READ, proto.bulk_read_params(requests))


def bulk_write(requests: Sequence[tuple[int, int, bytes]]) -> InstructionPacket:
    """BULK_WRITE (protocol 2): ``requests`` is a sequence of ``(id, address, data)``."""
    _check_motor_ids(r[0] for r in requests)
    parts = []
    for motor_id, address, data in requests:
        parts.append(
            bytes((motor_id,))
            + PROTOCOL_2.word(address, "address")
            + PROTOCOL_2.length_field(len(data))
        )
        parts.append(bytes(data))
    return InstructionPacket(BROADCAST_ID, Instruction.BULK_WRITE, b"".join(parts))


def usb2ax_sync_status(data: Sequence[bytes], error: int = 0) -> StatusPacket:
    """The USB2AX's answer to a protocol 1 sync read: one packet from ID 0xFD, data concatenated.

    Args:
        data: each motor's data in request order (0xFF bytes for a motor that did not answer).
        error: the error byte (the adapter only ever sets the range bit).
    """
    return StatusPacket(USB2AX_ID, error, b"".join(bytes(d) for d in data))


def parse_usb2ax_sync_status(
    packet: StatusPacket, length: int, ids: Sequence[int]
) -> dict[int, bytes]:
    """Split the USB2AX sync read answer into ``{id: data}`` (request order).

    Raises:
        ProtocolError: the packet is not from 0xFD or its size is not ``length * len(ids)``.
    """
    if packet.id != USB2AX_ID:
        raise ProtocolError(f"USB2AX sync read answer from ID {packet.id}, expected {USB2AX_ID}")
    if length < 1 or len(packet.params) != length * len(ids):
        raise ProtocolError(
            f"USB2AX sync read answer has {len(packet.params)} bytes, "
            f"expected {length} x {len(ids)}"
        )
    return {
        motor_id: packet.params[i * length : (i + 1) * length] for i, motor_id in enumerate(ids)
    }


# The parameter parsers live in their own module; they are reachable from here too.
from poppy_core.protocol.parsers import (  # noqa: E402
    parse_bulk_read,
    parse_bulk_write,
    parse_clear,
    parse_factory_reset,
    parse_read,
    parse_sync_read,
    parse_sync_write,
    parse_write,
)

__all__ = [
    "action",
    "bulk_read",
    "bulk_write",
    "clear",
    "factory_reset",
    "fast_sync_read",
    "parse_bulk_read",
    "parse_bulk_write",
    "parse_clear",
    "parse_factory_reset",
    "parse_read",
    "parse_sync_read",
    "parse_sync_write",
    "parse_usb2ax_sync_status",
    "parse_write",
    "ping",
    "read",
    "reboot",
    "reg_write",
    "sync_read",
    "sync_write",
    "usb2ax_sync_status",
    "write",
]
