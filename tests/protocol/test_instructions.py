"""Builders and parsers of instruction parameters, fast sync replies, errors, encode limits."""

from __future__ import annotations

import contextlib
from collections.abc import Callable

import pytest
from hypothesis import given
from hypothesis import strategies as st
from protocol_strategies import header_heavy_bytes, protocols

from poppy_core.errors import ProtocolError
from poppy_core.protocol import (
    BROADCAST_ID,
    Instruction,
    InstructionPacket,
    PacketDecoder,
    StatusPacket,
    action,
    bulk_read,
    bulk_write,
    clear,
    decode_errors,
    encode_fast_sync_status,
    encode_instruction,
    encode_status,
    factory_reset,
    fast_sync_read,
    parse_bulk_read,
    parse_bulk_write,
    parse_clear,
    parse_factory_reset,
    parse_fast_sync_status,
    parse_read,
    parse_sync_read,
    parse_sync_write,
    parse_usb2ax_sync_status,
    parse_write,
    ping,
    read,
    reboot,
    reg_write,
    sync_read,
    sync_write,
    usb2ax_sync_status,
    write,
)
from poppy_core.protocol import instructions as instructions_module

ids = st.integers(0, 253)
id_lists = st.lists(ids, min_size=1, max_size=20, unique=True)


def address(protocol: int) -> st.SearchStrategy[int]:
    return st.integers(0, 0xFF if protocol == 1 else 0xFFFF)


def through_wire(protocol: int, packet: InstructionPacket) -> InstructionPacket:
    [decoded] = PacketDecoder(protocol, "instruction").feed(encode_instruction(protocol, packet))
    assert isinstance(decoded, InstructionPacket)
    return decoded


@given(protocol=protocols, motor=ids, data=st.data())
def test_read_round_trip(protocol: int, motor: int, data: st.DataObject) -> None:
    addr = data.draw(address(protocol))
    length = data.draw(st.integers(1, 0xFF if protocol == 1 else 0xFFFF))
    packet = through_wire(protocol, read(protocol, motor, addr, length))
    assert (packet.id, packet.instruction) == (motor, Instruction.READ)
    assert parse_read(protocol, packet.params) == (addr, length)


@given(protocol=protocols, motor=ids, payload=header_heavy_bytes.filter(bool), data=st.data())
def test_write_and_reg_write_round_trip(
    protocol: int, motor: int, payload: bytes, data: st.DataObject
) -> None:
    addr = data.draw(address(protocol))
    for builder, code in ((write, Instruction.WRITE), (reg_write, Instruction.REG_WRITE)):
        packet = through_wire(protocol, builder(protocol, motor, addr, payload))
        assert packet.instruction == code
        assert parse_write(protocol, packet.params) == (addr, payload)


@given(protocol=protocols, motors=id_lists, data=st.data())
def test_sync_read_round_trip(protocol: int, motors: list[int], data: st.DataObject) -> None:
    addr = data.draw(address(protocol))
    length = data.draw(st.integers(1, 0xFF))
    packet = through_wire(protocol, sync_read(protocol, addr, length, motors))
    assert packet.id == BROADCAST_ID
    expected = Instruction.SYNC_READ if protocol == 2 else Instruction.SYNC_READ_USB2AX
    assert packet.instruction == expected
    assert parse_sync_read(protocol, packet.params) == (addr, length, motors)


@given(motors=id_lists, addr=st.integers(0, 0xFFFF), length=st.integers(1, 64))
def test_fast_sync_read_round_trip(motors: list[int], addr: int, length: int) -> None:
    packet = through_wire(2, fast_sync_read(addr, length, motors))
    assert packet.instruction == Instruction.FAST_SYNC_READ
    assert parse_sync_read(2, packet.params) == (addr, length, motors)


@given(protocol=protocols, length=st.integers(1, 8), data=st.data())
def test_sync_write_round_trip(protocol: int, length: int, data: st.DataObject) -> None:
    motors = data.draw(st.lists(ids, min_size=1, max_size=10, unique=True))
    chunks = {m: data.draw(st.binary(min_size=length, max_size=length)) for m in motors}
    addr = data.draw(address(protocol))
    packet = through_wire(protocol, sync_write(protocol, addr, length, chunks))
    assert packet.instruction == Instruction.SYNC_WRITE
    assert parse_sync_write(protocol, packet.params) == (addr, length, chunks)


@given(protocol=protocols, data=st.data())
def test_bulk_read_round_trip(protocol: int, data: st.DataObject) -> None:
    motors = data.draw(id_lists)
    limit = 0xFF if protocol == 1 else 0xFFFF
    requests = [(m, data.draw(address(protocol)), data.draw(st.integers(1, limit))) for m in motors]
    packet = through_wire(protocol, bulk_read(protocol, requests))
    assert packet.instruction == Instruction.BULK_READ
    assert parse_bulk_read(protocol, packet.params) == requests


@given(data=st.data())
def test_bulk_write_round_trip(data: st.DataObject) -> None:
    motors = data.draw(id_lists)
    requests = [
        (m, data.draw(st.integers(0, 0xFFFF)), data.draw(header_heavy_bytes.filter(bool)))
        for m in motors
    ]
    packet = through_wire(2, bulk_write(requests))
    assert packet.instruction == Instruction.BULK_WRITE
    assert parse_bulk_write(packet.params) == requests


def test_simple_instructions() -> None:
    assert ping(3) == InstructionPacket(3, Instruction.PING)
    assert action() == InstructionPacket(BROADCAST_ID, Instruction.ACTION)
    assert reboot(4) == InstructionPacket(4, Instruction.REBOOT)
    assert clear(5).params == b"\x01\x44\x58\x4c\x22"
    assert parse_clear(clear(5).params) == 0x01
    assert factory_reset(1, 2).params == b""
    assert parse_factory_reset(1, b"") == 0xFF
    for option in (0xFF, 0x01, 0x02):
        assert parse_factory_reset(2, factory_reset(2, 1, option).params) == option


def test_v1_bulk_read_layout_is_len_id_addr() -> None:
    assert bulk_read(1, [(1, 0x1E, 2)]).params == b"\x00\x02\x01\x1e"
    assert bulk_read(2, [(1, 0x84, 4)]).params == b"\x01\x84\x00\x04\x00"


def test_parsers_are_reachable_from_the_instructions_module() -> None:
    assert instructions_module.parse_read is parse_read
    assert instructions_module.parse_bulk_write is parse_bulk_write


@pytest.mark.parametrize(
    "call",
    [
        lambda: ping(255),
        lambda: ping(-1),
        lambda: read(1, 1, 256, 1),
        lambda: read(2, 1, 0x10000, 1),
        lambda: read(1, 1, 0, 0),
        lambda: read(3, 1, 0, 1),
        lambda: write(2, 1, 0, b""),
        lambda: factory_reset(2, 1, 0x03),
        lambda: factory_reset(1, 1, 0x01),
        lambda: sync_read(2, 0, 4, []),
        lambda: sync_read(2, 0, 4, [1, 1]),
        lambda: sync_read(2, 0, 4, [BROADCAST_ID]),
        lambda: fast_sync_read(0, 4, [300]),
        lambda: sync_write(2, 116, 4, {1: b"\x00"}),
        lambda: bulk_read(1, []),
        lambda: bulk_read(2, [(1, 0, 2), (1, 4, 2)]),
        lambda: bulk_write([(1, 0, b"")]),
    ],
)
def test_builders_reject_bad_arguments(call: object) -> None:
    with pytest.raises(ProtocolError):
        call()  # type: ignore[operator]


@pytest.mark.parametrize(
    ("parser", "params"),
    [
        (lambda p: parse_read(1, p), b"\x01"),
        (lambda p: parse_read(2, p), b"\x01\x00\x04"),
        (lambda p: parse_read(2, p), b"\x01\x00\x04\x00\x00"),
        (lambda p: parse_write(1, p), b"\x01"),
        (lambda p: parse_write(2, p), b"\x01\x00"),
        (lambda p: parse_sync_read(2, p), b"\x84\x00\x04\x00"),
        (lambda p: parse_sync_read(1, p), b"\x24\x00\x01"),
        (lambda p: parse_sync_read(2, p), b"\x84\x00\x04\x00\x01\x01"),
        (lambda p: parse_sync_read(2, p), b"\x84\x00\x04\x00\xfe"),
        (lambda p: parse_sync_write(2, p), b"\x74\x00\x04\x00\x01\x00\x00"),
        (lambda p: parse_sync_write(1, p), b"\x1e\x00\x01\x02"),
        (lambda p: parse_sync_write(1, p), b"\x1e\x01\x01\x02\x01\x03"),
        (lambda p: parse_bulk_read(1, p), b"\x01\x02\x01\x1e"),
        (lambda p: parse_bulk_read(1, p), b"\x00\x02\x01"),
        (lambda p: parse_bulk_read(1, p), b""),
        (lambda p: parse_bulk_read(2, p), b"\x01\x84\x00\x04"),
        (lambda p: parse_bulk_read(2, p), b"\x01\x84\x00\x00\x00"),
        (lambda p: parse_bulk_write(p), b""),
        (lambda p: parse_bulk_write(p), b"\x01\x74\x00\x04\x00\x00"),
        (lambda p: parse_bulk_write(p), b"\x01\x74\x00"),
        (lambda p: parse_factory_reset(1, p), b"\x01"),
        (lambda p: parse_factory_reset(2, p), b"\x05"),
        (lambda p: parse_factory_reset(2, p), b""),
        (lambda p: parse_clear(p), b"\x01\x44\x58\x4c"),
        (lambda p: parse_read(3, p), b"\x01\x02"),
    ],
)
def test_parsers_reject_bad_shapes(parser: object, params: bytes) -> None:
    with pytest.raises(ProtocolError):
        parser(params)  # type: ignore[operator]


@given(protocol=protocols, params=st.binary(max_size=40))
def test_parsers_raise_only_protocol_error(protocol: int, params: bytes) -> None:
    parsers: list[Callable[[], object]] = [
        lambda: parse_read(protocol, params),
        lambda: parse_write(protocol, params),
        lambda: parse_sync_read(protocol, params),
        lambda: parse_sync_write(protocol, params),
        lambda: parse_bulk_read(protocol, params),
        lambda: parse_bulk_write(params),
        lambda: parse_factory_reset(protocol, params),
        lambda: parse_clear(params),
    ]
    for parse in parsers:
        with contextlib.suppress(ProtocolError):
            parse()


# ------------------------------------------------------------ fast sync read replies


@given(length=st.integers(1, 8), data=st.data())
def test_fast_sync_status_round_trip(length: int, data: st.DataObject) -> None:
    motors = data.draw(st.lists(ids, min_size=1, max_size=12, unique=True))
    replies = [
        (m, data.draw(st.integers(0, 255)), data.draw(st.binary(min_size=length, max_size=length)))
        for m in motors
    ]
    wire = encode_fast_sync_status(replies)
    assert int.from_bytes(wire[5:7], "little") == 1 + len(motors) * (length + 4)
    [packet] = PacketDecoder(2, "status").feed(wire)
    assert isinstance(packet, StatusPacket)
    assert parse_fast_sync_status(packet, length) == {m: (e, d) for m, e, d in replies}


def test_fast_sync_status_layout() -> None:
    wire = encode_fast_sync_status([(1, 0, b"\xa6\x00\x00\x00"), (2, 0x80, b"\x1f\x08\x00\x00")])
    assert wire[:8] == bytes.fromhex("FF FF FD 00 FE 11 00 55")
    # Block 1: ERR ID DATA CRC, its CRC covering the packet from the header on.
    assert wire[8:14] == bytes.fromhex("00 01 A6 00 00 00")
    from poppy_core.protocol import crc16

    assert int.from_bytes(wire[14:16], "little") == crc16(wire[:14])
    assert wire[16:22] == bytes.fromhex("80 02 1F 08 00 00")
    assert int.from_bytes(wire[22:24], "little") == crc16(wire[:22])
    assert len(wire) == 24


def test_fast_sync_status_with_header_bytes_in_data_decodes() -> None:
    data = b"\xff\xff\xfd\xfd"
    wire = encode_fast_sync_status([(1, 0, data), (2, 0, data)])
    [packet] = PacketDecoder(2, "status").feed(wire)
    assert isinstance(packet, StatusPacket)
    assert parse_fast_sync_status(packet, 4) == {1: (0, data), 2: (0, data)}


@pytest.mark.parametrize(
    ("packet", "length"),
    [
        (StatusPacket(1, 0, b"\x01\x00\x00\x00\x00"), 4),
        (StatusPacket(BROADCAST_ID, 0, b"\x01\x00\x00"), 4),
        (StatusPacket(BROADCAST_ID, 0, b"\x01\x00"), 0),
        (StatusPacket(BROADCAST_ID, 0, b"\x01\xaa\x00\x00\x00\x01\xbb"), 1),
    ],
)
def test_parse_fast_sync_status_rejects_bad_shapes(packet: StatusPacket, length: int) -> None:
    with pytest.raises(ProtocolError):
        parse_fast_sync_status(packet, length)


def test_encode_fast_sync_status_rejects_bad_input() -> None:
    with pytest.raises(ProtocolError):
        encode_fast_sync_status([])
    with pytest.raises(ProtocolError):
        encode_fast_sync_status([(BROADCAST_ID, 0, b"\x00")])


# ------------------------------------------------------------ USB2AX sync read replies


@given(length=st.integers(1, 6), data=st.data())
def test_usb2ax_sync_status_round_trip(length: int, data: st.DataObject) -> None:
    motors = data.draw(st.lists(ids, min_size=1, max_size=32, unique=True))
    chunks = [data.draw(st.binary(min_size=length, max_size=length)) for _ in motors]
    [packet] = PacketDecoder(1, "status").feed(encode_status(1, usb2ax_sync_status(chunks)))
    assert isinstance(packet, StatusPacket)
    assert packet.id == 0xFD
    assert parse_usb2ax_sync_status(packet, length, motors) == dict(
        zip(motors, chunks, strict=True)
    )


def test_parse_usb2ax_sync_status_rejects_bad_shapes() -> None:
    with pytest.raises(ProtocolError):
        parse_usb2ax_sync_status(StatusPacket(1, 0, b"\x00\x00"), 2, [1])
    with pytest.raises(ProtocolError):
        parse_usb2ax_sync_status(StatusPacket(0xFD, 0, b"\x00\x00\x00"), 2, [1])


# ------------------------------------------------------------ error bits


def test_decode_errors_protocol_1() -> None:
    assert decode_errors(1, 0) == []
    assert decode_errors(1, 0x01) == ["input voltage"]
    assert decode_errors(1, 0x24) == ["overheating", "overload"]
    assert decode_errors(1, 0x7F) == [
        "input voltage",
        "angle limit",
        "overheating",
        "range",
        "checksum",
        "overload",
        "instruction",
    ]


def test_decode_errors_protocol_2() -> None:
    assert decode_errors(2, 0) == []
    assert decode_errors(2, 0x01) == ["result fail"]
    assert decode_errors(2, 0x03) == ["CRC error"]
    assert decode_errors(2, 0x07) == ["access error"]
    assert decode_errors(2, 0x80) == ["hardware alert"]
    assert decode_errors(2, 0x84) == ["data range error", "hardware alert"]
    assert decode_errors(2, 0x09) == ["error 9"]
    with pytest.raises(ProtocolError):
        decode_errors(3, 0)


# ------------------------------------------------------------ encode limits


@pytest.mark.parametrize("protocol", [1, 2])
def test_encode_rejects_bad_packets(protocol: int) -> None:
    with pytest.raises(ProtocolError):
        encode_instruction(protocol, InstructionPacket(0xFF, 1))
    with pytest.raises(ProtocolError):
        encode_instruction(protocol, InstructionPacket(1, 0x100))
    with pytest.raises(ProtocolError):
        encode_status(protocol, StatusPacket(1, 0x100))
    with pytest.raises(ProtocolError):
        encode_instruction(protocol, InstructionPacket(1, 3, bytes(5000)))
    with pytest.raises(ProtocolError):
        encode_instruction(3, ping(1))


def test_v1_parameter_limit() -> None:
    assert len(encode_instruction(1, InstructionPacket(1, 3, bytes(253)))) == 253 + 6
    with pytest.raises(ProtocolError):
        encode_instruction(1, InstructionPacket(1, 3, bytes(254)))


def test_packets_normalise_params_to_bytes() -> None:
    packet = InstructionPacket(1, 3, bytearray(b"\x01"))  # type: ignore[arg-type]
    assert type(packet.params) is bytes
    assert hash(packet) == hash(InstructionPacket(1, 3, b"\x01"))
