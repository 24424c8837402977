"""VirtualMotor firmware rules, exercised through VirtualBus.process (no port involved)."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from poppy_core.emulator import VirtualBus, build_bus_from_spec
from poppy_core.models import model_by_name
from poppy_core.protocol import (
    BROADCAST_ID,
    InstructionPacket,
    PacketDecoder,
    StatusPacket,
    action,
    decode_errors,
    encode_instruction,
    factory_reset,
    ping,
    read,
    reboot,
    reg_write,
    write,
)


def statuses(protocol: int, raw: bytes) -> list[StatusPacket]:
    return [p for p in PacketDecoder(protocol, "status").feed(raw) if isinstance(p, StatusPacket)]


def ask(
    bus: VirtualBus, packet: InstructionPacket, line_bps: int | None = None
) -> list[StatusPacket]:
    out = bus.process(encode_instruction(bus.protocol, packet), line_bps=line_bps)
    return statuses(bus.protocol, out)


def addr(bus: VirtualBus, motor_id: int, name: str) -> tuple[int, int]:
    register = bus.motor(motor_id).model.register(name)
    return register.address, register.size


def write_reg(bus: VirtualBus, motor_id: int, name: str, raw: int) -> list[StatusPacket]:
    register = bus.motor(motor_id).model.register(name)
    return ask(bus, write(bus.protocol, motor_id, register.address, register.encode(raw)))


def read_reg(bus: VirtualBus, motor_id: int, name: str) -> int:
    register = bus.motor(motor_id).model.register(name)
    (reply,) = ask(bus, read(bus.protocol, motor_id, register.address, register.size))
    return register.decode(reply.params)


@pytest.fixture
def xl() -> VirtualBus:
    return build_bus_from_spec("XL-320:1-3", auto_step=False)


@pytest.fixture
def mxb() -> VirtualBus:
    return build_bus_from_spec("MX-28:11-13,AX-12A:36", auto_step=False)


def test_ping_v2_gives_model_number_and_firmware(xl: VirtualBus) -> None:
    (reply,) = ask(xl, ping(2))
    assert reply.id == 2 and reply.error == 0
    assert int.from_bytes(reply.params[:2], "little") == 350
    assert len(reply.params) == 3


def test_ping_v1_has_no_params(mxb: VirtualBus) -> None:
    assert ask(mxb, ping(11)) == [StatusPacket(11, 0, b"")]
    assert ask(mxb, ping(99)) == []


def test_broadcast_v1_ping_is_not_answered(mxb: VirtualBus) -> None:
    assert ask(mxb, ping(BROADCAST_ID)) == []


def test_read_model_number_and_sensors(mxb: VirtualBus) -> None:
    assert read_reg(mxb, 11, "model_number") == model_by_name("MX-28").model_number
    assert read_reg(mxb, 36, "model_number") == model_by_name("AX-12A").model_number
    volts = mxb.motor(11).model.register("present_voltage")
    assert volts.to_si(read_reg(mxb, 11, "present_voltage")) == pytest.approx(12.0)
    temp = mxb.motor(11).model.register("present_temperature")
    assert temp.to_si(read_reg(mxb, 11, "present_temperature")) == pytest.approx(35.0)


def test_xl320_reports_its_nominal_voltage(xl: VirtualBus) -> None:
    volts = xl.motor(1).model.register("present_voltage")
    assert volts.to_si(read_reg(xl, 1, "present_voltage")) == pytest.approx(7.4)


def test_write_then_read_back(xl: VirtualBus) -> None:
    assert write_reg(xl, 1, "goal_position", 700) == [StatusPacket(1, 0, b"")]
    assert read_reg(xl, 1, "goal_position") == 700


def test_read_only_write_v2_access_error(xl: VirtualBus) -> None:
    (reply,) = write_reg(xl, 1, "present_position", 10)
    assert decode_errors(2, reply.error) == ["access error"]


def test_read_only_write_v1_range_error(mxb: VirtualBus) -> None:
    (reply,) = write_reg(mxb, 11, "present_position", 10)
    assert decode_errors(1, reply.error) == ["range"]


def test_value_out_of_range(xl: VirtualBus, mxb: VirtualBus) -> None:
    (reply,) = write_reg(xl, 1, "status_return_level", 3)
    assert decode_errors(2, reply.error) == ["data range error"]
    (reply,) = write_reg(mxb, 11, "status_return_level", 7)
    assert decode_errors(1, reply.error) == ["range"]
    assert read_reg(mxb, 11, "status_return_level") == 2


def test_partial_register_write_v2_is_a_length_error(xl: VirtualBus) -> None:
    address, _ = addr(xl, 1, "goal_position")
    (reply,) = ask(xl, write(2, 1, address, b"\x10"))
    assert decode_errors(2, reply.error) == ["data length error"]


def test_goal_outside_angle_limits(mxb: VirtualBus, xl: VirtualBus) -> None:
    write_reg(mxb, 11, "ccw_angle_limit", 3000)
    (reply,) = write_reg(mxb, 11, "goal_position", 3500)
    assert decode_errors(1, reply.error) == ["angle limit"]
    assert read_reg(mxb, 11, "goal_position") != 3500
    write_reg(xl, 1, "ccw_angle_limit", 800)
    (reply,) = write_reg(xl, 1, "goal_position", 900)
    assert decode_errors(2, reply.error) == ["data limit error"]


def test_wheel_mode_has_no_angle_limit(mxb: VirtualBus) -> None:
    write_reg(mxb, 36, "cw_angle_limit", 0)
    write_reg(mxb, 36, "ccw_angle_limit", 0)
    assert write_reg(mxb, 36, "goal_position", 1000)[0].error == 0


@pytest.mark.parametrize("spec", ["XL-320:1", "XM430-W350:1"])
def test_eeprom_locked_while_torque_on_protocol2(spec: str) -> None:
    bus = build_bus_from_spec(spec, auto_step=False)
    write_reg(bus, 1, "torque_enable", 1)
    (reply,) = write_reg(bus, 1, "return_delay_time", 10)
    assert decode_errors(2, reply.error) == ["access error"]
    write_reg(bus, 1, "torque_enable", 0)
    assert write_reg(bus, 1, "return_delay_time", 10)[0].error == 0
    assert read_reg(bus, 1, "return_delay_time") == 10


def test_eeprom_writable_with_torque_on_protocol1(mxb: VirtualBus) -> None:
    write_reg(mxb, 11, "torque_enable", 1)
    assert write_reg(mxb, 11, "return_delay_time", 10)[0].error == 0


def test_eeprom_lock_register_v1(mxb: VirtualBus) -> None:
    write_reg(mxb, 12, "lock", 1)
    (reply,) = write_reg(mxb, 12, "return_delay_time", 10)
    assert reply.error != 0


def test_status_return_level(xl: VirtualBus) -> None:
    assert write_reg(xl, 1, "status_return_level", 1) == [StatusPacket(1, 0, b"")]
    assert write_reg(xl, 1, "led", 1) == []
    assert read_reg(xl, 1, "led") == 1
    write_reg(xl, 1, "status_return_level", 0)
    address, size = addr(xl, 1, "led")
    assert ask(xl, read(2, 1, address, size)) == []
    assert len(ask(xl, ping(1))) == 1


def test_broadcast_write_applies_silently(xl: VirtualBus) -> None:
    address, _ = addr(xl, 1, "led")
    assert ask(xl, write(2, BROADCAST_ID, address, b"\x02")) == []
    assert [read_reg(xl, i, "led") for i in (1, 2, 3)] == [2, 2, 2]


def test_reg_write_waits_for_action(xl: VirtualBus) -> None:
    address, _ = addr(xl, 2, "led")
    assert ask(xl, reg_write(2, 2, address, b"\x04"))[0].error == 0
    assert read_reg(xl, 2, "led") == 0
    assert read_reg(xl, 2, "registered") == 1
    assert ask(xl, action()) == []
    assert read_reg(xl, 2, "led") == 4
    assert read_reg(xl, 2, "registered") == 0


def test_action_without_reg_write(mxb: VirtualBus) -> None:
    (reply,) = ask(mxb, action(11))
    assert decode_errors(1, reply.error) == ["instruction"]


def test_unknown_instruction(mxb: VirtualBus) -> None:
    (reply,) = ask(mxb, InstructionPacket(11, 0x08))  # REBOOT is not protocol 1
    assert decode_errors(1, reply.error) == ["instruction"]


def test_id_change_replies_from_old_id(xl: VirtualBus) -> None:
    (reply,) = write_reg(xl, 3, "id", 9)
    assert reply.id == 3
    assert ask(xl, ping(3)) == []
    assert ask(xl, ping(9))[0].id == 9


def test_factory_reset_v1_resets_id_and_baud(mxb: VirtualBus) -> None:
    write_reg(mxb, 13, "return_delay_time", 3)
    (reply,) = ask(mxb, factory_reset(1, 13))
    assert reply.id == 13
    motor = mxb.motors[2]
    assert motor.id == 1
    assert motor.baudrate_bps == 57_600  # e-manual MX-28: factory baud rate 57 600 bps
    assert motor.table.get("return_delay_time") == motor.model.register("return_delay_time").default


@pytest.mark.parametrize(
    ("option", "expected_id", "expected_bps"),
    [(0xFF, 1, 57_600), (0x01, 5, 57_600), (0x02, 5, 1_000_000)],
)
def test_factory_reset_v2_options(option: int, expected_id: int, expected_bps: int) -> None:
    # e-manual XM430-W350: factory id 1, factory baud rate 57 600 bps.
    bus = build_bus_from_spec("XM430-W350:5", auto_step=False, baudrate=1_000_000)
    (reply,) = ask(bus, factory_reset(2, 5, option))
    assert reply.id == 5
    motor = bus.motors[0]
    assert (motor.id, motor.baudrate_bps) == (expected_id, expected_bps)


def test_broadcast_factory_reset_all_is_ignored_v2(xl: VirtualBus) -> None:
    ask(xl, factory_reset(2, BROADCAST_ID, 0xFF))
    assert [m.id for m in xl.motors] == [1, 2, 3]


def test_reboot_restores_ram_and_clears_faults(xl: VirtualBus) -> None:
    write_reg(xl, 1, "led", 3)
    xl.motor(1).fail_with(["input voltage"])
    assert ask(xl, ping(1))[0].error & 0x80
    assert ask(xl, reboot(1))[0].id == 1
    assert read_reg(xl, 1, "led") == 0
    assert ask(xl, ping(1))[0].error == 0


def test_fail_with_overload_v1_sets_bit_and_shuts_down(mxb: VirtualBus) -> None:
    write_reg(mxb, 11, "torque_enable", 1)
    mxb.motor(11).fail_with(["overload"])
    (reply,) = ask(mxb, ping(11))
    assert "overload" in decode_errors(1, reply.error)
    assert read_reg(mxb, 11, "torque_enable") == 0
    mxb.motor(11).clear_faults()
    assert ask(mxb, ping(11))[0].error == 0


def test_fail_with_v2_sets_hardware_error_status(xl: VirtualBus) -> None:
    xl.motor(2).fail_with(["overload"])
    (reply,) = ask(xl, ping(2))
    assert decode_errors(2, reply.error) == ["hardware alert"]
    assert read_reg(xl, 2, "hardware_error_status") == 0x01
    with pytest.raises(ValueError):
        xl.motor(2).fail_with(["no such error"])


def test_checksum_error_reply(mxb: VirtualBus, xl: VirtualBus) -> None:
    bad = bytearray(encode_instruction(1, ping(12)))
    bad[-1] ^= 0x55
    replies = statuses(1, mxb.process(bytes(bad)))
    assert [(r.id, decode_errors(1, r.error)) for r in replies] == [(12, ["checksum"])]
    bad = bytearray(encode_instruction(2, read(2, 1, 30, 2)))
    bad[-1] ^= 0x55
    replies = statuses(2, xl.process(bytes(bad)))
    assert [(r.id, decode_errors(2, r.error)) for r in replies] == [(1, ["CRC error"])]
    assert xl.corrupt_packets == 1


def test_line_speed_mismatch_is_silence(xl: VirtualBus) -> None:
    assert ask(xl, ping(1), line_bps=57_600) == []
    assert ask(xl, ping(1), line_bps=1_020_000) != []  # 2 % off: a UART still decodes it


def test_baud_change_takes_effect_after_reply(xl: VirtualBus) -> None:
    (reply,) = write_reg(xl, 1, "baudrate", xl.motor(1).model.baudrate_code(115_200))
    assert reply.id == 1
    assert ask(xl, ping(1)) == []
    assert ask(xl, ping(1), line_bps=115_200)[0].id == 1


def test_duplicate_ids_collide(xl: VirtualBus) -> None:
    write_reg(xl, 2, "id", 1)
    raw = xl.process(encode_instruction(2, ping(1)))
    assert raw  # both answered at once: bytes on the line ...
    decoder = PacketDecoder(2, "status")
    assert len(decoder.feed(raw)) < 2  # ... but not two clean packets


@settings(max_examples=200, deadline=None)
@given(st.binary(max_size=300), st.sampled_from([1, 2]))
def test_random_bytes_never_crash(data: bytes, protocol: int) -> None:
    spec = "XL-320:1-2" if protocol == 2 else "AX-12A:1-2"
    bus = build_bus_from_spec(spec, auto_step=False)
    out = bus.process(data)
    decoder = PacketDecoder(protocol, "status")
    replies = decoder.feed(out)
    ids = [m.id for m in bus.motors]
    if len(set(ids)) == len(ids):  # no id collision: every reply is a clean status packet
        assert decoder.corrupt_packets == 0 and decoder.pending == 0
    assert all(0 <= r.id <= 252 for r in replies)


@settings(max_examples=100, deadline=None)
@given(st.integers(0, 60), st.binary(min_size=1, max_size=8))
def test_random_writes_answer_once_from_the_old_id(address: int, data: bytes) -> None:
    bus = build_bus_from_spec("XL-320:1", auto_step=False)
    replies = ask(bus, write(2, 1, address, data))
    assert [r.id for r in replies] == [1]
