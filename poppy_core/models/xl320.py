"""XL-320 control table (protocol 2.0, AX-like units)."""

from __future__ import annotations

from enum import Enum

from poppy_core.models.converters import (
    BOOL,
    LOAD_PERCENT,
    RAW,
    RETURN_DELAY,
    TEMPERATURE,
    TORQUE_PERCENT,
    VOLTAGE,
    Baudrate,
    Choice,
    DirectionBit,
    gain,
    position,
)
from poppy_core.models.model import ServoModel, aliases_for
from poppy_core.models.register import build_table

# e-manual (XL-320, "Baud Rate (4)").
XL320_BAUDRATES: dict[int, int] = {0: 9_600, 1: 57_600, 2: 115_200, 3: 1_000_000}

# e-manual (XL-320, "LED(25)"): bit 0 red, bit 1 green, bit 2 blue. The e-manual calls 5 "Purple";
# poppy (like pypot) names it "pink" and accepts "purple" when writing.
XL320_LED = Choice(
    names=(
        (0, "off"),
        (1, "red"),
        (2, "green"),
        (3, "yellow"),
        (4, "blue"),
        (5, "pink"),
        (6, "cyan"),
        (7, "white"),
    ),
    synonyms=(("purple", 5),),
    mask=0x07,
    on="white",  # "on" lights all three LEDs
)


class XL320LEDColors(Enum):
    """pypot's enum of the LED colours (``pypot.dynamixel.conversion``): each is its register
    code + 1 (``XL320LEDColors(code + 1).name``, ``XL320LEDColors.red.value - 1``)."""

    off = 1
    red = 2
    green = 3
    yellow = 4
    blue = 5
    pink = 6
    cyan = 7
    white = 8


_POSITION = position(300.0, 1024)
# e-manual: Moving Speed / Present Speed unit about 0.111 rpm (joint mode), bit 10 = CW.
_SPEED = DirectionBit(0.111 * 6.0, "deg/s")

# e-manual: https://emanual.robotis.com/docs/en/dxl/x/xl320/ (control table; specifications:
# stall torque 0.39 N·m at 7.4 V, no-load speed 114 rpm at 7.4 V). PID gains use the MX scaling
# (the page includes the MX PID description).
_REGISTERS = build_table(
    [
        # name, address, size, access, default, min_raw, max_raw, conversion
        ("model_number", 0, 2, "R", 350, 0, 0xFFFF, RAW),
        ("firmware", 2, 1, "R", None, 0, 0xFF, RAW),
        ("id", 3, 1, "RW", 1, 0, 252, RAW),
        ("baudrate", 4, 1, "RW", 3, 0, 3, Baudrate(tuple(XL320_BAUDRATES.items()))),
        ("return_delay_time", 5, 1, "RW", 250, 0, 254, RETURN_DELAY),
        ("cw_angle_limit", 6, 2, "RW", 0, 0, 1023, _POSITION),
        ("ccw_angle_limit", 8, 2, "RW", 1023, 0, 1023, _POSITION),
        ("control_mode", 11, 1, "RW", 2, 1, 2, RAW),
        ("temperature_limit", 12, 1, "RW", 65, 0, 150, TEMPERATURE),
        ("min_voltage_limit", 13, 1, "RW", 60, 50, 250, VOLTAGE),
        ("max_voltage_limit", 14, 1, "RW", 90, 50, 250, VOLTAGE),
        ("max_torque", 15, 2, "RW", 1023, 0, 1023, TORQUE_PERCENT),
        ("status_return_level", 17, 1, "RW", 2, 0, 2, RAW),
        ("shutdown", 18, 1, "RW", 3, 0, 7, RAW),
        ("torque_enable", 24, 1, "RW", 0, 0, 1, BOOL),
        ("led", 25, 1, "RW", 0, 0, 7, XL320_LED),
        ("d_gain", 27, 1, "RW", 0, 0, 254, gain(4 / 1000)),
        ("i_gain", 28, 1, "RW", 0, 0, 254, gain(1000 / 2048)),
        ("p_gain", 29, 1, "RW", 32, 0, 254, gain(1 / 8)),
        ("goal_position", 30, 2, "RW", None, 0, 1023, _POSITION),
        ("moving_speed", 32, 2, "RW", None, 0, 2047, _SPEED),
        # The e-manual gives "-" as default; the servo copies Max Torque at power-on like the AX.
        ("torque_limit", 35, 2, "RW", 1023, 0, 1023, TORQUE_PERCENT),
        ("present_position", 37, 2, "R", None, 0, 1023, _POSITION),
        ("present_speed", 39, 2, "R", None, 0, 2047, _SPEED),
        ("present_load", 41, 2, "R", None, 0, 2047, LOAD_PERCENT),
        ("present_voltage", 45, 1, "R", None, 0, 255, VOLTAGE),
        ("present_temperature", 46, 1, "R", None, 0, 255, TEMPERATURE),
        ("registered", 47, 1, "R", 0, 0, 1, BOOL),
        ("moving", 49, 1, "R", 0, 0, 1, BOOL),
        ("hardware_error_status", 50, 1, "R", 0, 0, 255, RAW),
        ("punch", 51, 2, "RW", 32, 0, 1023, RAW),
    ],
    ram_start=24,
)

XL_320 = ServoModel(
    name="XL-320",
    model_numbers=(350,),
    protocol=2,
    registers=_REGISTERS,
    aliases=aliases_for(_REGISTERS, xseries=False),
    position_range_deg=300.0,
    resolution=1024,
    no_load_speed_dps=114.0 * 6.0,
    stall_torque_nm=0.39,
    baudrates=XL320_BAUDRATES,
    has_torque_limit=True,
)
