"""Who answers an instruction packet on the line, and in what order (sync, bulk, broadcast)."""

from __future__ import annotations

import logging
from dataclasses import dataclass
from typing import TYPE_CHECKING

from poppy_core.emulator.wire_timing import transfer_time_s
from poppy_core.errors import ProtocolError
from poppy_core.protocol import (
    BROADCAST_ID,
    USB2AX_ID,
    Instruction,
    InstructionPacket,
    StatusPacket,
    encode_fast_sync_status,
    encode_instruction,
    encode_status,
    parse_bulk_read,
    parse_bulk_write,
    parse_sync_read,
    parse_sync_write,
    read,
    usb2ax_sync_status,
)

if TYPE_CHECKING:
    from poppy_core.emulator.bus import VirtualBus
    from poppy_core.emulator.motor import VirtualMotor

logger = logging.getLogger(__name__)

# Idle UART line is high: when two motors talk at once, a 0 bit wins (open-drain TTL bus).
_IDLE = 0xFF


@dataclass(frozen=True)
class ReplyFrame:
    """One reply on the line: bytes, the silence before them, whether they take line time."""

    data: bytes
    delay_s: float
    on_wire: bool = True

    @classmethod
    def status(cls, protocol: int, motor: VirtualMotor, packet: StatusPacket) -> ReplyFrame:
        """A motor's status packet, sent after its return delay."""
        return cls(encode_status(protocol, packet), motor.return_delay_s)


def _collide(frames: list[ReplyFrame]) -> ReplyFrame:
    """Several motors answering at once: the bytes overlap (AND of the levels)."""
    size = max(len(frame.data) for frame in frames)
    out = bytearray([_IDLE] * size)
    for frame in frames:
        for i, byte in enumerate(frame.data):
            out[i] &= byte
    return ReplyFrame(bytes(out), min(frame.delay_s for frame in frames))


def _listener(bus: VirtualBus, motor_id: int, line: int) -> VirtualMotor | None:
    for motor in bus.motors:
        if motor.id == motor_id and bus.hears(motor, line):
            return motor
    return None


def supports(motor: VirtualMotor, instruction: int) -> bool:
    """Whether the motor's firmware knows ``instruction`` among the multi-motor ones.

    e-manual: protocol 1 Bulk Read exists on MX (and later) firmware, not on AX (which speaks
    only protocol 1); protocol 2 Fast Sync Read exists on X-series (firmware 45+), not on XL-320.
    """
    name = motor.model.name.upper()
    if instruction == Instruction.BULK_READ:
        return not name.startswith("AX")
    if instruction == Instruction.FAST_SYNC_READ:
        return not name.startswith("XL-320")
    return True


def dispatch(bus: VirtualBus, packet: InstructionPacket, line: int) -> list[ReplyFrame]:
    """Execute ``packet`` on every motor that hears it; return the replies in line order."""
    ins = packet.instruction
    try:
        if ins == Instruction.SYNC_READ_USB2AX and bus.proto.usb2ax_sync_read:
            return _usb2ax_sync_read(bus, packet, line)
        if packet.id == BROADCAST_ID and ins in (
            Instruction.SYNC_READ,
            Instruction.FAST_SYNC_READ,
            Instruction.BULK_READ,
            Instruction.SYNC_WRITE,
            Instruction.BULK_WRITE,
        ):
            return _group(bus, packet, line)
    except ProtocolError as exc:
        logger.debug("malformed group instruction %#04x ignored: %s", ins, exc)
        return []
    if (
        bus.adapter == "usb2ax"
        and bus.proto.usb2ax_sync_read
        and packet.id == USB2AX_ID
        and ins == Instruction.PING
    ):
        return [ReplyFrame(encode_status(1, StatusPacket(USB2AX_ID, 0)), 0.0, on_wire=False)]
    frames: list[ReplyFrame] = []
    targets = [
        motor
        for motor in bus.motors
        if (packet.id == BROADCAST_ID or motor.id == packet.id) and bus.hears(motor, line)
    ]
    for motor in sorted(targets, key=lambda m: m.id):
        status = motor.handle(packet)
        if status is not None:
            frames.append(ReplyFrame.status(bus.protocol, motor, status))
    if packet.id != BROADCAST_ID and len(frames) > 1:
        return [_collide(frames)]
    return frames


def _group(bus: VirtualBus, packet: InstructionPacket, line: int) -> list[ReplyFrame]:
    proto, ins, params = bus.proto, packet.instruction, packet.params
    if ins == Instruction.SYNC_WRITE:
        address, _, data = parse_sync_write(proto, params)
        for motor_id, chunk in data.items():
            motor = _listener(bus, motor_id, line)
            if motor is not None:
                motor.write_block(address, chunk)
        return []
    if ins == Instruction.BULK_WRITE:
        if not proto.has_bulk_write:
            return []
        for motor_id, address, chunk in parse_bulk_write(params):
            motor = _listener(bus, motor_id, line)
            if motor is not None:
                motor.write_block(address, chunk)
        return []
    if ins == Instruction.BULK_READ:
        requests = parse_bulk_read(proto, params)
    elif proto.has_sync_read:
        address, length, ids = parse_sync_read(proto, params)
        requests = [(motor_id, address, length) for motor_id in ids]
    else:
        return []
    return _read_chain(bus, ins, requests, line)


def _read_chain(
    bus: VirtualBus, ins: int, requests: list[tuple[int, int, int]], line: int
) -> list[ReplyFrame]:
    """Motors answer in request order, each after the previous one's status packet.

    A motor that does not answer breaks the chain: the next ones wait for its status forever
    (Robotis, DynamixelSDK issue #364: "if one device does not respond in the middle, all IDs
    do not respond after that"). Protocol 1 bulk read works the same way (e-manual, MX Bulk
    Read: each motor waits for the previous one).
    """
    blocks: list[tuple[VirtualMotor, int, bytes]] = []
    for motor_id, address, length in requests:
        motor = _listener(bus, motor_id, line)
        if motor is None or not supports(motor, ins) or motor.status_return_level < 1:
            break
        code, data = motor.read_block(address, length)
        blocks.append((motor, code, data))
    if ins != Instruction.FAST_SYNC_READ:
        return [
            ReplyFrame.status(bus.protocol, motor, motor.status(code, data))
            for motor, code, data in blocks
        ]
    if not blocks:
        return []
    length = requests[0][2]
    parts = [
        (motor.id, motor.error_byte(code), data if len(data) == length else bytes(length))
        for motor, code, data in blocks
    ]
    if len(blocks) == len(requests):
        return [ReplyFrame(encode_fast_sync_status(parts), blocks[0][0].return_delay_s)]
    # A missing motor: the combined packet announces every block but stops where it would be.
    missing = [(motor_id, 0, bytes(length)) for motor_id, _, _ in requests[len(blocks) :]]
    whole = encode_fast_sync_status(parts + missing)
    sent = len(encode_fast_sync_status(parts))
    return [ReplyFrame(whole[:sent], blocks[0][0].return_delay_s)]


def _usb2ax_sync_read(bus: VirtualBus, packet: InstructionPacket, line: int) -> list[ReplyFrame]:
    """USB2AX sync read (0x84): the adapter reads each motor itself and answers once.

    USB2AX firmware (advanced_commands.txt): a motor that does not answer leaves 0xFF bytes.
    Any other adapter does not know 0x84: the broadcast packet is ignored by every motor.
    """
    if bus.adapter != "usb2ax" or packet.id not in (BROADCAST_ID, USB2AX_ID):
        return []
    address, length, ids = parse_sync_read(1, packet.params)
    chunks: list[bytes] = []
    bus_time = 0.0
    for motor_id in ids:
        request = encode_instruction(1, read(1, motor_id, address, length))
        bus_time += transfer_time_s(len(request), line)
        motor = _listener(bus, motor_id, line)
        code, data = (1, b"") if motor is None else motor.read_block(address, length)
        if motor is None or code or motor.status_return_level < 1:
            chunks.append(bytes([0xFF] * length))
            continue
        bus_time += motor.return_delay_s + transfer_time_s(6 + length, line)
        chunks.append(data)
    return [ReplyFrame(encode_status(1, usb2ax_sync_status(chunks)), bus_time, on_wire=False)]
