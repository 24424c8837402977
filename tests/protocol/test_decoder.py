"""PacketDecoder: round trips, any chunking, garbage, corruption, kinds, counters, fuzzing."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from protocol_strategies import (
    header_heavy_bytes,
    instruction_packets,
    kinds,
    packets_of,
    protocols,
    status_packets,
)

from poppy_core.errors import ProtocolError
from poppy_core.protocol import (
    V2_MAX_LENGTH,
    InstructionPacket,
    PacketDecoder,
    StatusPacket,
    encode_instruction,
    encode_status,
    ping,
    read,
    write,
)


def encode(protocol: int, packet: InstructionPacket | StatusPacket) -> bytes:
    if isinstance(packet, InstructionPacket):
        return encode_instruction(protocol, packet)
    return encode_status(protocol, packet)


def feed_in_chunks(decoder: PacketDecoder, data: bytes, cuts: list[int]) -> list[object]:
    out: list[object] = []
    positions = sorted({c % (len(data) + 1) for c in cuts})
    start = 0
    for pos in [*positions, len(data)]:
        out += decoder.feed(data[start:pos])
        start = pos
    return out


@given(
    protocol=protocols,
    packets=st.lists(instruction_packets(), min_size=1, max_size=5),
    cuts=st.lists(st.integers(0, 10_000), max_size=12),
)
def test_instruction_round_trip_in_any_split(
    protocol: int, packets: list[InstructionPacket], cuts: list[int]
) -> None:
    wire = b"".join(encode_instruction(protocol, p) for p in packets)
    decoder = PacketDecoder(protocol, "instruction")
    assert feed_in_chunks(decoder, wire, cuts) == packets
    assert (decoder.corrupt_packets, decoder.skipped_bytes, decoder.pending) == (0, 0, 0)


@given(
    protocol=protocols,
    packets=st.lists(status_packets(), min_size=1, max_size=5),
    cuts=st.lists(st.integers(0, 10_000), max_size=12),
)
def test_status_round_trip_in_any_split(
    protocol: int, packets: list[StatusPacket], cuts: list[int]
) -> None:
    wire = b"".join(encode_status(protocol, p) for p in packets)
    decoder = PacketDecoder(protocol, "status")
    assert feed_in_chunks(decoder, wire, cuts) == packets
    assert (decoder.corrupt_packets, decoder.skipped_bytes, decoder.pending) == (0, 0, 0)


def longest_frame(protocol: int) -> int:
    return 4 + 255 if protocol == 1 else 7 + V2_MAX_LENGTH


def feed_until_recovered(
    decoder: PacketDecoder, protocol: int, prefix: bytes, wire: bytes, cuts: list[int]
) -> list[object]:
    """Feed prefix + packet, then more copies of the packet: a bogus header with a long LEN may
    hold the decoder until that many bytes have arrived (or until the bus resets it)."""
    found = feed_in_chunks(decoder, prefix + wire + wire, cuts)
    copies = longest_frame(protocol) // len(wire) + 2
    return found + decoder.feed(wire * copies)


@given(
    protocol=protocols,
    kind=kinds,
    garbage=header_heavy_bytes,
    cuts=st.lists(st.integers(0, 10_000), max_size=8),
    data=st.data(),
)
def test_valid_packet_after_garbage_is_recovered(
    protocol: int, kind: str, garbage: bytes, cuts: list[int], data: st.DataObject
) -> None:
    packet = data.draw(packets_of(kind))
    decoder = PacketDecoder(protocol, kind)  # type: ignore[arg-type]
    found = feed_until_recovered(decoder, protocol, garbage, encode(protocol, packet), cuts)
    assert found[-1] == packet


@given(
    protocol=protocols,
    kind=kinds,
    data=st.data(),
    flip=st.integers(0, 10_000),
    mask=st.integers(1, 255),
)
def test_valid_packet_after_corrupted_packet_is_recovered(
    protocol: int, kind: str, data: st.DataObject, flip: int, mask: int
) -> None:
    strategy = packets_of(kind)
    bad_source = data.draw(strategy)
    good = data.draw(strategy)
    bad = bytearray(encode(protocol, bad_source))
    bad[flip % len(bad)] ^= mask
    decoder = PacketDecoder(protocol, kind)  # type: ignore[arg-type]
    found = feed_until_recovered(decoder, protocol, bytes(bad), encode(protocol, good), [])
    assert found[-1] == good


@given(kind=kinds, data=st.data(), cut=st.integers(0, 10_000))
def test_v2_corrupted_header_hiding_a_packet_recovers_without_waiting(
    kind: str, data: st.DataObject, cut: int
) -> None:
    strategy = packets_of(kind)
    good = data.draw(strategy)
    # A truncated packet whose LEN claims far more bytes than follow: the real header that
    # comes next is an unstuffed FF FF FD 00 inside the claimed payload, so it is rejected.
    bogus = b"\xff\xff\xfd\x00\x01\x00\x08\x03\x00"
    wire = bogus[: 5 + cut % 5] + encode(2, good) if cut % 2 else bogus + encode(2, good)
    decoder = PacketDecoder(2, kind)  # type: ignore[arg-type]
    assert decoder.feed(wire) == [good]
    assert decoder.pending == 0


@settings(max_examples=300)
@given(
    protocol=protocols,
    kind=kinds,
    stream=st.binary(max_size=400),
    cuts=st.lists(st.integers(0, 10_000), max_size=20),
)
def test_feed_never_raises_and_accounts_for_every_byte(
    protocol: int, kind: str, stream: bytes, cuts: list[int]
) -> None:
    decoder = PacketDecoder(protocol, kind)  # type: ignore[arg-type]
    found = feed_in_chunks(decoder, stream, cuts)
    for packet in found:
        assert isinstance(packet, InstructionPacket if kind == "instruction" else StatusPacket)
    assert decoder.skipped_bytes + decoder.pending <= len(stream)
    assert decoder.pending <= len(stream)


@settings(max_examples=200)
@given(protocol=protocols, kind=kinds, stream=header_heavy_bytes)
def test_header_heavy_noise_never_raises(protocol: int, kind: str, stream: bytes) -> None:
    decoder = PacketDecoder(protocol, kind)  # type: ignore[arg-type]
    for _ in range(3):
        decoder.feed(stream)


def test_garbage_before_header_is_skipped_and_counted() -> None:
    decoder = PacketDecoder(2, "status")
    wire = encode_status(2, StatusPacket(3, 0, b"\x01"))
    assert decoder.feed(b"\x12\x34\x56" + wire) == [StatusPacket(3, 0, b"\x01")]
    assert decoder.skipped_bytes == 3
    assert decoder.corrupt_packets == 0


def test_bad_crc_counts_corrupt_and_finds_packet_inside() -> None:
    good = encode_status(2, StatusPacket(5, 0, b"\xaa"))
    # A header that claims a length covering the good packet, with a wrong CRC.
    fake = b"\xff\xff\xfd\x00\x01\x0e\x00\x55\x00"
    decoder = PacketDecoder(2, "status")
    found = decoder.feed(fake + good + b"\x00" * 8)
    assert StatusPacket(5, 0, b"\xaa") in found
    assert decoder.corrupt_packets == 1


def test_v1_bad_checksum_then_good_packet() -> None:
    good = encode_instruction(1, ping(7))
    bad = bytearray(encode_instruction(1, read(1, 2, 36, 2)))
    bad[-1] ^= 0xFF
    decoder = PacketDecoder(1, "instruction")
    assert decoder.feed(bytes(bad) + good) == [ping(7)]
    assert decoder.corrupt_packets == 1


def test_v1_extra_ff_before_header() -> None:
    decoder = PacketDecoder(1, "status")
    assert decoder.feed(b"\xff" + encode_status(1, StatusPacket(1, 0))) == [StatusPacket(1, 0)]
    assert decoder.skipped_bytes == 1


@pytest.mark.parametrize("length", [b"\x00\x00", b"\x02\x00", b"\xff\xff"])
def test_v2_impossible_length_is_corrupt(length: bytes) -> None:
    decoder = PacketDecoder(2, "instruction")
    good = encode_instruction(2, ping(1))
    assert decoder.feed(b"\xff\xff\xfd\x00\x01" + length + good) == [ping(1)]
    assert decoder.corrupt_packets == 1


def test_v1_impossible_length_is_corrupt() -> None:
    decoder = PacketDecoder(1, "instruction")
    assert decoder.feed(b"\xff\xff\x01\x01" + encode_instruction(1, ping(1))) == [ping(1)]
    assert decoder.corrupt_packets == 1


def test_v2_status_decoder_ignores_echo_of_instruction() -> None:
    decoder = PacketDecoder(2, "status")
    echo = encode_instruction(2, read(2, 1, 132, 4))
    reply = encode_status(2, StatusPacket(1, 0, b"\x01\x02\x03\x04"))
    assert decoder.feed(echo + reply) == [StatusPacket(1, 0, b"\x01\x02\x03\x04")]
    assert decoder.ignored_packets == 1
    assert decoder.corrupt_packets == 0


def test_v2_instruction_decoder_ignores_status() -> None:
    decoder = PacketDecoder(2, "instruction")
    status = encode_status(2, StatusPacket(1, 0))
    assert decoder.feed(status + encode_instruction(2, ping(2))) == [ping(2)]
    assert decoder.ignored_packets == 1


def test_status_without_error_byte_is_corrupt() -> None:
    decoder = PacketDecoder(2, "status")
    # LEN 3: INS 0x55 and CRC only, with a correct CRC.
    frame = encode_instruction(2, InstructionPacket(1, 0x55))
    assert decoder.feed(frame + encode_status(2, StatusPacket(1, 0))) == [StatusPacket(1, 0)]
    assert decoder.corrupt_packets == 1


def test_partial_packet_is_pending_and_reset_drops_it() -> None:
    wire = encode_instruction(2, write(2, 1, 116, b"\x00\x02\x00\x00"))
    decoder = PacketDecoder(2, "instruction")
    assert decoder.feed(wire[:9]) == []
    assert decoder.pending == 9
    decoder.reset()
    assert decoder.pending == 0
    assert decoder.feed(wire[9:]) == []
    assert decoder.feed(wire) == [write(2, 1, 116, b"\x00\x02\x00\x00")]


def test_partial_header_at_end_is_kept() -> None:
    wire = encode_instruction(2, ping(1))
    decoder = PacketDecoder(2, "instruction")
    assert decoder.feed(b"\x01\x02" + wire[:3]) == []
    assert decoder.pending == 3
    assert decoder.skipped_bytes == 2
    assert decoder.feed(wire[3:]) == [ping(1)]


def test_byte_by_byte() -> None:
    wire = encode_status(1, StatusPacket(4, 0x20, b"\x10\x20")) * 2
    decoder = PacketDecoder(1, "status")
    found = [p for b in wire for p in decoder.feed(bytes((b,)))]
    assert found == [StatusPacket(4, 0x20, b"\x10\x20")] * 2


def test_accepts_bytearray_and_memoryview() -> None:
    wire = encode_instruction(2, ping(1))
    assert PacketDecoder(2, "instruction").feed(bytearray(wire)) == [ping(1)]
    assert PacketDecoder(2, "instruction").feed(memoryview(wire)) == [ping(1)]


@pytest.mark.parametrize(("protocol", "kind"), [(3, "status"), (2, "echo"), (0, "instruction")])
def test_bad_constructor_arguments(protocol: int, kind: str) -> None:
    with pytest.raises(ProtocolError):
        PacketDecoder(protocol, kind)  # type: ignore[arg-type]
