"""The protocol objects: one shared object per version, its sizes and capabilities (e-manual)."""

from __future__ import annotations

import pytest

from poppy_core.errors import ProtocolError
from poppy_core.protocol import (
    PROTOCOL_1,
    PROTOCOL_2,
    PROTOCOLS_BY_VERSION,
    DxlProtocol,
    Instruction,
    StatusPacket,
    decode_errors,
    encode_status,
    ping,
    protocol_for,
)


def test_protocol_for_gives_one_shared_object_per_version() -> None:
    assert protocol_for(1) is PROTOCOL_1 and protocol_for(2) is PROTOCOL_2
    assert protocol_for(PROTOCOL_2) is PROTOCOL_2
    assert dict(PROTOCOLS_BY_VERSION) == {1: PROTOCOL_1, 2: PROTOCOL_2}
    assert all(isinstance(p, DxlProtocol) for p in PROTOCOLS_BY_VERSION.values())
    assert repr(PROTOCOL_2) == "<Dynamixel protocol 2>"


@pytest.mark.parametrize("bad", [0, 3, "2", None, 1.5])
def test_unknown_protocols_are_refused(bad: object) -> None:
    with pytest.raises(ProtocolError, match="expected 1 or 2"):
        protocol_for(bad)  # type: ignore[arg-type]


def test_capabilities_follow_the_e_manual() -> None:
    # Protocol 2 adds broadcast ping, sync/fast sync read, bulk write, reboot, clear and the
    # factory reset options; protocol 1 has only the USB2AX adapter's sync read.
    v1, v2 = PROTOCOL_1, PROTOCOL_2
    for name in (
        "has_broadcast_ping",
        "has_sync_read",
        "has_fast_sync_read",
        "has_bulk_write",
        "has_reboot",
        "has_clear",
        "has_factory_reset_options",
    ):
        assert (getattr(v1, name), getattr(v2, name)) == (False, True), name
    assert (v1.usb2ax_sync_read, v2.usb2ax_sync_read) == (True, False)
    assert (v1.sync_read_instruction, v2.sync_read_instruction) == (
        Instruction.SYNC_READ_USB2AX,
        Instruction.SYNC_READ,
    )
    assert (v1.max_motor_id, v2.max_motor_id) == (253, 252)
    assert (v1.word(0x12, "address"), v2.word(0x1234, "address")) == (b"\x12", b"\x34\x12")


@pytest.mark.parametrize("proto", [PROTOCOL_1, PROTOCOL_2])
def test_sizes_match_the_encoded_packets(proto: DxlProtocol) -> None:
    assert len(proto.encode_instruction(ping(1))) == proto.instruction_size(0)
    status = StatusPacket(1, 0, bytes(proto.ping_params))
    assert len(encode_status(proto.version, status)) == proto.status_size(proto.ping_params)
    assert proto.header == proto.encode_instruction(ping(1))[: len(proto.header)]


def test_error_bytes_alarms_and_names() -> None:
    # Protocol 1: overload (bit 5) is an alarm; range (bit 3) is a refusal.
    assert PROTOCOL_1.is_alarm_only(0x20) and not PROTOCOL_1.is_alarm_only(0x28)
    assert PROTOCOL_1.error_byte(0x08, 0x20) == 0x28
    assert PROTOCOL_1.decode_errors(0x28) == decode_errors(1, 0x28) == ["range", "overload"]
    # Protocol 2: the alert bit alone is an alarm; the faults only raise that bit.
    assert PROTOCOL_2.is_alarm_only(0x80) and not PROTOCOL_2.is_alarm_only(0x87)
    assert PROTOCOL_2.error_byte(0x07, 0x05) == 0x87
    assert PROTOCOL_2.decode_errors(0x87) == ["access error", "hardware alert"]
    assert not PROTOCOL_1.is_alarm_only(0) and not PROTOCOL_2.is_alarm_only(0)


def test_ping_payloads() -> None:
    assert PROTOCOL_1.ping_reply(12, 24) == b"" and PROTOCOL_1.ping_identity(b"") is None
    reply = PROTOCOL_2.ping_reply(1060, 45)
    assert reply == b"\x24\x04\x2d" and PROTOCOL_2.ping_identity(reply) == (1060, 45)
