"""Known byte vectors from the Robotis e-manual (protocol 1.0 and 2.0) and the USB2AX docs."""

from __future__ import annotations

import pytest

from poppy_core.protocol import (
    BROADCAST_ID,
    InstructionPacket,
    PacketDecoder,
    StatusPacket,
    action,
    bulk_read,
    checksum,
    clear,
    crc16,
    encode_instruction,
    encode_status,
    factory_reset,
    parse_usb2ax_sync_status,
    ping,
    read,
    reboot,
    reg_write,
    sync_read,
    sync_write,
    write,
)


def hx(text: str) -> bytes:
    return bytes.fromhex(text)


V2_INSTRUCTIONS = [
    # e-manual Protocol 2.0, Ping example
    (ping(1), "FF FF FD 00 01 03 00 01 19 4E"),
    # Read: Present Position (132), 4 bytes
    (read(2, 1, 132, 4), "FF FF FD 00 01 07 00 02 84 00 04 00 1D 15"),
    # Write: Goal Position (116) = 512
    (write(2, 1, 116, bytes([0, 2, 0, 0])), "FF FF FD 00 01 09 00 03 74 00 00 02 00 00 CA 89"),
    # Reg Write: Goal Velocity (104) = 200
    (
        reg_write(2, 1, 104, bytes([200, 0, 0, 0])),
        "FF FF FD 00 01 09 00 04 68 00 C8 00 00 00 AE 8E",
    ),
    (action(1), "FF FF FD 00 01 03 00 05 02 CE"),
    # Factory reset, all but ID
    (factory_reset(2, 1, 0x01), "FF FF FD 00 01 04 00 06 01 A1 E6"),
    (reboot(1), "FF FF FD 00 01 03 00 08 2F 4E"),
    # Clear multi-turn
    (clear(1), "FF FF FD 00 01 08 00 10 01 44 58 4C 22 B1 DC"),
    # Sync Read of Present Position from IDs 1 and 2
    (sync_read(2, 132, 4, [1, 2]), "FF FF FD 00 FE 09 00 82 84 00 04 00 01 02 CE FA"),
    # Sync Write Goal Position 150 to ID 1, 170 to ID 2
    (
        sync_write(2, 116, 4, {1: bytes([0x96, 0, 0, 0]), 2: bytes([0xAA, 0, 0, 0])}),
        "FF FF FD 00 FE 11 00 83 74 00 04 00 01 96 00 00 00 02 AA 00 00 00 82 87",
    ),
]

V2_STATUS = [
    # Ping reply: model 1030 (XM430-W350), firmware 0x26
    (StatusPacket(1, 0, bytes([0x06, 0x04, 0x26])), "FF FF FD 00 01 07 00 55 00 06 04 26 65 5D"),
    # Read reply: present position 166
    (StatusPacket(1, 0, bytes([0xA6, 0, 0, 0])), "FF FF FD 00 01 08 00 55 00 A6 00 00 00 8C C0"),
    # Write reply
    (StatusPacket(1, 0), "FF FF FD 00 01 04 00 55 00 A1 0C"),
]

V1_INSTRUCTIONS = [
    # e-manual Protocol 1.0 examples (AX/MX)
    (ping(1), "FF FF 01 02 01 FB"),
    (read(1, 1, 0x2B, 1), "FF FF 01 04 02 2B 01 CC"),
    (write(1, BROADCAST_ID, 0x03, b"\x01"), "FF FF FE 04 03 03 01 F6"),
    (factory_reset(1, 0), "FF FF 00 02 06 F7"),
    (
        sync_write(
            1,
            0x1E,
            4,
            {
                0: bytes([0x10, 0x00, 0x50, 0x01]),
                1: bytes([0x20, 0x02, 0x60, 0x03]),
                2: bytes([0x30, 0x00, 0x70, 0x01]),
                3: bytes([0x20, 0x02, 0x80, 0x03]),
            },
        ),
        "FF FF FE 18 83 1E 04 00 10 00 50 01 01 20 02 60 03 02 30 00 70 01 03 20 02 80 03 12",
    ),
    # MX Bulk Read: 2 bytes at 0x1E from ID 1, 2 bytes at 0x24 from ID 2
    (bulk_read(1, [(1, 0x1E, 2), (2, 0x24, 2)]), "FF FF FE 09 92 00 02 01 1E 02 02 24 1D"),
]

V1_STATUS = [
    (StatusPacket(1, 0), "FF FF 01 02 00 FC"),
    (StatusPacket(1, 0, b"\x20"), "FF FF 01 03 00 20 DB"),
]


@pytest.mark.parametrize(("packet", "wire"), V2_INSTRUCTIONS)
def test_v2_instruction_vectors(packet: InstructionPacket, wire: str) -> None:
    assert encode_instruction(2, packet) == hx(wire)
    assert PacketDecoder(2, "instruction").feed(hx(wire)) == [packet]


@pytest.mark.parametrize(("packet", "wire"), V2_STATUS)
def test_v2_status_vectors(packet: StatusPacket, wire: str) -> None:
    assert encode_status(2, packet) == hx(wire)
    assert PacketDecoder(2, "status").feed(hx(wire)) == [packet]


@pytest.mark.parametrize(("packet", "wire"), V1_INSTRUCTIONS)
def test_v1_instruction_vectors(packet: InstructionPacket, wire: str) -> None:
    assert encode_instruction(1, packet) == hx(wire)
    assert PacketDecoder(1, "instruction").feed(hx(wire)) == [packet]


@pytest.mark.parametrize(("packet", "wire"), V1_STATUS)
def test_v1_status_vectors(packet: StatusPacket, wire: str) -> None:
    assert encode_status(1, packet) == hx(wire)
    assert PacketDecoder(1, "status").feed(hx(wire)) == [packet]


def test_crc16_matches_the_ping_example() -> None:
    assert crc16(hx("FF FF FD 00 01 03 00 01")) == 0x4E19


def test_crc16_can_continue_a_running_value() -> None:
    data = hx("FF FF FD 00 01 07 00 02 84 00 04 00")
    assert crc16(data[5:], crc16(data[:5])) == crc16(data) == 0x151D


def test_v1_checksum() -> None:
    assert checksum(hx("01 04 02 2B 01")) == 0xCC


def test_usb2ax_sync_read_example() -> None:
    # USB2AX advanced_commands.txt: present position + speed of IDs 0, 1, 2, 7. The adapter
    # doc's example addresses the adapter (0xFD); we send to broadcast, which it also accepts.
    assert encode_instruction(1, InstructionPacket(0xFD, 0x84, hx("24 04 00 01 02 07"))) == hx(
        "FF FF FD 08 84 24 04 00 01 02 07 44"
    )
    assert encode_instruction(1, sync_read(1, 0x24, 4, [0, 1, 2, 7])) == hx(
        "FF FF FE 08 84 24 04 00 01 02 07 43"
    )
    reply = hx("FF FF FD 12 00 50 01 FF 01 20 00 00 02 10 00 10 02 00 00 FE 01 5C")
    [status] = PacketDecoder(1, "status").feed(reply)
    assert isinstance(status, StatusPacket)
    assert parse_usb2ax_sync_status(status, 4, [0, 1, 2, 7]) == {
        0: hx("50 01 FF 01"),
        1: hx("20 00 00 02"),
        2: hx("10 00 10 02"),
        7: hx("00 00 FE 01"),
    }


def test_v2_stuffing_example() -> None:
    # Params FF FF FD get an extra FD; LEN counts it, and the decoder removes it again.
    packet = write(2, 1, 0x0000, hx("FF FF FD"))
    wire = encode_instruction(2, packet)
    assert wire[:7] == hx("FF FF FD 00 01 09 00")  # INS + 6 stuffed params + CRC
    assert wire[7:-2] == hx("03 00 00 FF FF FD FD")
    assert PacketDecoder(2, "instruction").feed(wire) == [packet]
