"""Conversions checked against facts from the Robotis e-manual."""

from __future__ import annotations

import math

import pytest

from poppy_core.errors import RegisterError
from poppy_core.models import (
    AX_12A,
    AX_18A,
    MX_12W,
    MX_28,
    MX_64,
    XL330_M288,
    XL430_W250,
    XL_320,
    XM430_W350,
)


def test_ax_position_is_centred_on_512() -> None:
    reg = AX_12A.register("present_position")
    assert reg.to_si(512) == 0.0
    assert reg.to_si(1023) == pytest.approx(150.0, abs=0.5)
    assert reg.to_si(0) == pytest.approx(-150.0)
    assert AX_12A.register("goal_position").from_si(0.0) == 512


def test_mx_and_x_positions_are_centred_on_2048() -> None:
    assert MX_28.register("present_position").to_si(2048) == 0.0
    assert MX_28.register("present_position").to_si(3072) == pytest.approx(90.0)
    assert XL430_W250.register("present_position").to_si(2048) == 0.0
    assert XL430_W250.register("goal_position").from_si(-90.0) == 1024


def test_x_position_accepts_multi_turn_values() -> None:
    reg = XM430_W350.register("present_position")
    assert reg.to_si(2048 + 4096) == pytest.approx(360.0)
    # An unsigned two's-complement value read from the wire is decoded first.
    assert reg.to_si(0xFFFFFFFF) == pytest.approx(-2049 * 360 / 4096)


def test_present_load_direction_bit() -> None:
    reg = AX_12A.register("present_load")
    assert reg.to_si(100) == pytest.approx(10.0)  # CCW load: positive
    assert reg.to_si(1124) == pytest.approx(-10.0)  # bit 10 set: CW load, negative
    assert reg.from_si(-10.0) == 1124
    assert reg.to_si(512) == pytest.approx(51.2)


def test_present_speed_direction_bit_in_deg_per_s() -> None:
    ax = AX_12A.register("present_speed")
    assert ax.to_si(300) == pytest.approx(300 * 0.111 * 6)  # 33.3 rpm CCW
    assert ax.to_si(1024 + 300) == pytest.approx(-300 * 0.111 * 6)
    mx = MX_28.register("present_speed")
    assert mx.to_si(300) == pytest.approx(34.2 * 6, rel=1e-3)  # e-manual: 300 → about 34.2 rpm
    assert MX_12W.register("present_speed").to_si(300) == pytest.approx(274.8 * 6)


def test_moving_speed_zero_means_max_speed_and_reads_as_zero() -> None:
    reg = MX_28.register("moving_speed")
    assert reg.to_si(0) == 0.0
    assert reg.from_si(0.0) == 0
    assert reg.to_si(1023) == pytest.approx(116.62 * 6, rel=1e-3)  # e-manual: about 116.62 rpm


def test_zero_and_1024_both_read_zero_and_round_trip() -> None:
    reg = AX_12A.register("present_speed")
    assert reg.to_si(1024) == 0.0
    assert reg.from_si(reg.to_si(1024)) == 1024
    assert reg.from_si(reg.to_si(0)) == 0


def test_x_velocity_is_signed_0229_rpm() -> None:
    reg = XL430_W250.register("present_velocity")
    assert reg.to_si(100) == pytest.approx(100 * 0.229 * 6)
    assert reg.to_si(-100) == pytest.approx(-100 * 0.229 * 6)
    assert reg.signed and reg.size == 4


def test_voltage_temperature_delay() -> None:
    assert AX_12A.register("present_voltage").to_si(120) == pytest.approx(12.0)
    assert XL430_W250.register("present_voltage").to_si(120) == pytest.approx(12.0)
    assert MX_28.register("present_temperature").to_si(85) == 85.0
    assert AX_12A.register("return_delay_time").to_si(250) == pytest.approx(500.0)
    assert AX_12A.register("return_delay_time").unit == "µs"


def test_torque_percentages() -> None:
    reg = AX_12A.register("torque_limit")
    assert reg.to_si(1023) == pytest.approx(100.0)
    assert reg.to_si(512) == pytest.approx(50.05, abs=0.01)
    assert reg.from_si(100.0) == 1023
    assert AX_18A.register("max_torque").default == 983


def test_mx_pid_gains_use_emanual_scaling() -> None:
    assert MX_28.register("p_gain").to_si(32) == pytest.approx(4.0)  # Kp = P / 8
    assert MX_28.register("i_gain").to_si(2048) == pytest.approx(1000.0)  # Ki = I * 1000 / 2048
    assert MX_28.register("d_gain").to_si(250) == pytest.approx(1.0)  # Kd = D * 4 / 1000
    assert XL430_W250.register("position_p_gain").to_si(640) == pytest.approx(5.0)


def test_mx_current_and_goal_torque() -> None:
    assert MX_64.register("current").to_si(2148) == pytest.approx(450.0)  # e-manual example
    assert MX_64.register("goal_torque").to_si(1024 + 100) == pytest.approx(-450.0)


def test_x_current_in_milliamps() -> None:
    assert XM430_W350.register("present_current").to_si(100) == pytest.approx(269.0)
    assert XM430_W350.register("present_current").to_si(0xFFFF) == pytest.approx(-2.69)
    assert XL330_M288.register("present_current").to_si(-100) == pytest.approx(-100.0)


def test_protocol1_baudrates() -> None:
    assert AX_12A.baudrate_bps(1) == 1_000_000
    assert AX_12A.baudrate_bps(34) == 57_600
    assert AX_12A.baudrate_code(57_600) == 34
    assert AX_12A.baudrate_code(57_142) == 34
    assert AX_12A.baudrate_code(117_647) == 16
    assert MX_28.baudrate_bps(0) == 2_000_000
    assert AX_12A.baudrate_bps(254) == 7843  # e-manual: "7843 bps ~ 1 Mbps"
    assert MX_28.baudrate_bps(250) == 2_250_000
    assert MX_28.baudrate_bps(252) == 3_000_000
    assert MX_28.baudrate_code(3_000_000) == 252
    with pytest.raises(RegisterError):
        AX_12A.baudrate_bps(0)  # AX tops out at 1 Mbps
    with pytest.raises(RegisterError):
        MX_28.baudrate_bps(253)
    with pytest.raises(RegisterError, match="baudrate"):
        AX_12A.baudrate_code(3_000_000)


def test_protocol2_baudrates() -> None:
    assert XL_320.baudrate_bps(3) == 1_000_000
    assert XL_320.baudrate_code(115_200) == 2
    assert XL430_W250.baudrate_bps(7) == 4_500_000
    assert XL430_W250.baudrate_code(9_600) == 0
    with pytest.raises(RegisterError):
        XL330_M288.baudrate_code(4_500_000)
    with pytest.raises(RegisterError):
        XL_320.baudrate_code(2_000_000)
    with pytest.raises(RegisterError):
        XL_320.baudrate_bps(4)


def test_xl320_led_colours() -> None:
    reg = XL_320.register("led")
    assert reg.to_si(2) == "green"
    assert reg.to_si(0) == "off"
    assert reg.to_si(7) == "white"
    assert reg.from_si("Cyan") == 6
    assert reg.from_si("purple") == 5
    assert reg.from_si(4) == 4
    with pytest.raises(RegisterError, match="led"):
        reg.from_si("magenta")
    with pytest.raises(RegisterError):
        reg.from_si(8)


def test_bool_registers() -> None:
    reg = MX_28.register("torque_enable")
    assert reg.to_si(1) is True
    assert reg.to_si(0) is False
    assert reg.from_si(True) == 1
    assert reg.from_si(0) == 0
    assert XL430_W250.register("led").to_si(1) is True
    with pytest.raises(RegisterError):
        reg.from_si(2)
    with pytest.raises(RegisterError):
        reg.from_si("on")


def test_out_of_range_message_names_register_value_and_range() -> None:
    with pytest.raises(RegisterError) as info:
        AX_12A.register("goal_position").from_si(200.0)
    message = str(info.value)
    assert "goal_position" in message and "200.0" in message
    assert "-150" in message and "149.7" in message and "deg" in message
    assert "\n" not in message
    assert info.value.register == "goal_position"


@pytest.mark.parametrize("bad", [math.nan, math.inf, "12", None, [1]])
def test_from_si_rejects_non_numbers(bad: object) -> None:
    with pytest.raises(RegisterError):
        AX_12A.register("goal_position").from_si(bad)


def test_direction_bit_magnitude_limit() -> None:
    reg = AX_12A.register("moving_speed")
    top = reg.to_si(1023)
    assert isinstance(top, float)
    assert reg.from_si(-top) == 2047
    with pytest.raises(RegisterError):
        reg.from_si(top * 1.01)


def test_read_only_registers_convert_but_are_not_writable() -> None:
    reg = AX_12A.register("present_position")
    assert not reg.writable
    assert reg.from_si(0.0) == 512
    assert AX_12A.register("goal_position").writable


def test_decode_and_encode_bytes() -> None:
    reg = XL430_W250.register("present_velocity")
    assert reg.decode(b"\xff\xff\xff\xff") == -1
    assert reg.encode(-1) == b"\xff\xff\xff\xff"
    assert AX_12A.register("goal_position").encode(512) == b"\x00\x02"
    with pytest.raises(RegisterError):
        AX_12A.register("goal_position").encode(70000)
    with pytest.raises(RegisterError):
        reg.decode(b"\x00")


def test_parse_turns_typed_text_into_si_values() -> None:
    import pytest

    from poppy_core.errors import RegisterError
    from poppy_core.models import model_by_name

    mx, xl = model_by_name("MX-28"), model_by_name("XL-320")
    assert mx.register("torque_enable").parse("on") is True
    assert mx.register("torque_enable").parse("OFF") is False
    assert mx.register("goal_position").parse("30") == 30
    assert mx.register("goal_position").parse("-12.5") == -12.5
    assert xl.register("led").parse("Green") == "green"
    assert xl.register("led").parse("2") == 2
    with pytest.raises(RegisterError, match="takes a number in deg"):
        mx.register("goal_position").parse("thirty")
    with pytest.raises(RegisterError, match="on or off"):
        mx.register("torque_enable").parse("maybe")


def test_on_and_off_are_one_mapping() -> None:
    """The XL-320 LED takes colours: "on" is white (all three LEDs), "off" is off; on/off
    registers take booleans. The bus IO, the CLI and the TUI all ask ``Register.switched``."""
    led = XL_320.register("led")
    assert (led.switched(True), led.switched(False)) == ("white", "off")
    assert led.parse("on") == led.parse(" ON ") == "white"
    assert led.parse("off") == "off" and led.parse("3") == 3
    for register in (AX_12A.register("led"), XL_320.register("torque_enable")):
        assert (register.switched(True), register.switched(False)) == (True, False)
    with pytest.raises(RegisterError, match="on/off"):
        XL_320.register("goal_position").switched(True)


def test_decode_si_reads_a_register_wherever_its_bytes_start() -> None:
    table = bytearray(MX_28.table_size)
    position = MX_28.register("goal_position")
    table[position.address : position.address + 2] = position.encode(3072)
    expected = position.to_si(3072)
    assert position.decode_si(bytes(table), start=0) == expected
    assert position.decode_si(bytes(table[position.address :])) == expected
    assert position.decode_si(bytes(table[20:]), start=20) == expected
    with pytest.raises(RegisterError):
        position.decode_si(bytes(table[:31]), start=0)  # ends inside the register
    with pytest.raises(RegisterError):
        position.decode_si(bytes(table[40:]), start=40)  # starts after it


def test_decode_table_gives_the_registers_the_bytes_hold() -> None:
    table = bytes(XL_320.table_size)
    values = XL_320.decode_table(table)
    assert list(values) == [
        r.name for r in sorted(XL_320.registers.values(), key=lambda r: r.address)
    ]
    assert values["led"] == "off" and values["goal_position"] == XL_320.register(
        "goal_position"
    ).to_si(0)
    goal = XL_320.register("goal_position")
    names = ["goal_position", "moving_speed", "led", "no_such"]
    part = XL_320.decode_table(table[goal.address : goal.address + 4], names, start=goal.address)
    assert set(part) == {"goal_position", "moving_speed"}  # led lies outside, no_such is unknown
