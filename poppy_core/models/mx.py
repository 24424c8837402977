"""MX-12W, MX-28, MX-64 and MX-106 control tables (protocol 1.0 firmware)."""

from __future__ import annotations

from poppy_core.models.ax import (
    PROTOCOL1_CLOCK_BPS,
    PROTOCOL1_LISTED_BAUDRATES,
    PROTOCOL1_RAM_START,
)
from poppy_core.models.converters import (
    BOOL,
    LOAD_PERCENT,
    MILLISECONDS,
    RAW,
    RETURN_DELAY,
    TEMPERATURE,
    TORQUE_PERCENT,
    VOLTAGE,
    Baudrate,
    DirectionBit,
    Linear,
    gain,
    position,
)
from poppy_core.models.model import ServoModel, aliases_for
from poppy_core.models.register import Row, build_table

# e-manual (MX-28, "Baud Rate (4)"): codes 250-252 give 2.25, 2.5 and 3 Mbps; the rest follow
# 2,000,000 / (code + 1) like the AX.
MX_LISTED_BAUDRATES: dict[int, int] = {
    **PROTOCOL1_LISTED_BAUDRATES,
    250: 2_250_000,
    251: 2_500_000,
    252: 3_000_000,
}
MX_BAUDRATE = Baudrate(
    tuple(MX_LISTED_BAUDRATES.items()), clock_bps=PROTOCOL1_CLOCK_BPS, max_code=252
)
MX_POSITION = position(360.0, 4096)
# Multi Turn Offset is in position ticks, without the centring offset.
MX_TICKS_DEG = Linear(360.0 / 4096, "deg")
# e-manual (control_table_mx_pid): Kp = P / 8, Ki = I * 1000 / 2048, Kd = D * 4 / 1000.
MX_P_GAIN = gain(1 / 8)
MX_I_GAIN = gain(1000 / 2048)
MX_D_GAIN = gain(4 / 1000)
# e-manual (MX-64 "Current (68)"): I = 4.5 mA * (raw - 2048).
# e-manual (MX-64 "Goal Torque (71)"): 4.5 mA per unit, bit 10 = CW.
MX_CURRENT = Linear(4.5, "mA", 2048)
MX_GOAL_TORQUE = DirectionBit(4.5, "mA")
# e-manual (Goal Acceleration (73)): about 8.583 °/s² per unit.
MX_GOAL_ACCELERATION = Linear(8.583, "deg/s²")


def _mx_rows(
    *,
    model_number: int,
    baudrate: int,
    max_voltage_limit: int,
    pid: tuple[int, int, int],
    punch: int,
    speed_rpm: float,
) -> list[Row]:
    speed = DirectionBit(speed_rpm * 6.0, "deg/s")
    d_gain, i_gain, p_gain = pid
    return [
        # name, address, size, access, default, min_raw, max_raw, conversion
        ("model_number", 0, 2, "R", model_number, 0, 0xFFFF, RAW),
        ("firmware", 2, 1, "R", None, 0, 0xFF, RAW),
        ("id", 3, 1, "RW", 1, 0, 253, RAW),
        ("baudrate", 4, 1, "RW", baudrate, 0, 252, MX_BAUDRATE),
        ("return_delay_time", 5, 1, "RW", 250, 0, 254, RETURN_DELAY),
        ("cw_angle_limit", 6, 2, "RW", 0, 0, 4095, MX_POSITION),
        ("ccw_angle_limit", 8, 2, "RW", 4095, 0, 4095, MX_POSITION),
        ("temperature_limit", 11, 1, "RW", 80, 0, 150, TEMPERATURE),
        ("min_voltage_limit", 12, 1, "RW", 60, 50, 250, VOLTAGE),
        ("max_voltage_limit", 13, 1, "RW", max_voltage_limit, 50, 250, VOLTAGE),
        ("max_torque", 14, 2, "RW", 1023, 0, 1023, TORQUE_PERCENT),
        ("status_return_level", 16, 1, "RW", 2, 0, 2, RAW),
        ("alarm_led", 17, 1, "RW", 36, 0, 127, RAW),
        ("shutdown", 18, 1, "RW", 36, 0, 127, RAW),
        ("multi_turn_offset", 20, 2, "RW", 0, -24576, 24576, MX_TICKS_DEG),
        ("resolution_divider", 22, 1, "RW", 1, 1, 4, RAW),
        ("torque_enable", 24, 1, "RW", 0, 0, 1, BOOL),
        ("led", 25, 1, "RW", 0, 0, 1, BOOL),
        ("d_gain", 26, 1, "RW", d_gain, 0, 254, MX_D_GAIN),
        ("i_gain", 27, 1, "RW", i_gain, 0, 254, MX_I_GAIN),
        ("p_gain", 28, 1, "RW", p_gain, 0, 254, MX_P_GAIN),
        ("goal_position", 30, 2, "RW", None, 0, 4095, MX_POSITION),
        ("moving_speed", 32, 2, "RW", None, 0, 2047, speed),
        ("torque_limit", 34, 2, "RW", 1023, 0, 1023, TORQUE_PERCENT),
        ("present_position", 36, 2, "R", None, 0, 4095, MX_POSITION),
        ("present_speed", 38, 2, "R", None, 0, 2047, speed),
        ("present_load", 40, 2, "R", None, 0, 2047, LOAD_PERCENT),
        ("present_voltage", 42, 1, "R", None, 0, 255, VOLTAGE),
        ("present_temperature", 43, 1, "R", None, 0, 255, TEMPERATURE),
        ("registered", 44, 1, "R", 0, 0, 1, BOOL),
        ("moving", 46, 1, "R", 0, 0, 1, BOOL),
        ("lock", 47, 1, "RW", 0, 0, 1, BOOL),
        ("punch", 48, 2, "RW", punch, 0, 1023, RAW),
        ("realtime_tick", 50, 2, "R", 0, 0, 32767, MILLISECONDS),
    ]


# e-manual (MX-64 / MX-106, RAM area): current sensing and torque control.
_TORQUE_CONTROL_ROWS: list[Row] = [
    ("current", 68, 2, "RW", 0, 0, 4095, MX_CURRENT),
    ("torque_control_mode_enable", 70, 1, "RW", 0, 0, 1, BOOL),
    ("goal_torque", 71, 2, "RW", 0, 0, 2047, MX_GOAL_TORQUE),
]
_GOAL_ACCELERATION_ROW: Row = ("goal_acceleration", 73, 1, "RW", 0, 0, 254, MX_GOAL_ACCELERATION)
# e-manual (MX-106, "Drive Mode (10)"): dual-joint (master/slave, reverse) settings, kept raw.
_DRIVE_MODE_ROW: Row = ("drive_mode", 10, 1, "RW", 0, 0, 255, RAW)


def _mx_model(
    name: str,
    model_numbers: tuple[int, ...],
    rows: list[Row],
    no_load_rpm: float,
    stall_torque_nm: float,
) -> ServoModel:
    registers = build_table(sorted(rows, key=lambda row: row[1]), PROTOCOL1_RAM_START)
    return ServoModel(
        name=name,
        model_numbers=model_numbers,
        protocol=1,
        registers=registers,
        aliases=aliases_for(registers, xseries=False),
        position_range_deg=360.0,
        resolution=4096,
        no_load_speed_dps=no_load_rpm * 6.0,
        stall_torque_nm=stall_torque_nm,
        baudrates=MX_LISTED_BAUDRATES,
        has_torque_limit=True,
    )


# e-manual: https://emanual.robotis.com/docs/en/dxl/mx/mx-12w/ (control table: baud rate 1,
# D/I/P 8/0/8, punch 32, speed unit 0.916 rpm; no-load speed 470 rpm at 12 V). The page lists model
# number 104 while the firmware, Dynamixel Wizard and the SDK report 360 (0x168): both are accepted.
# Stall torque is not on the current page; 0.2 N·m is the older Robotis support page's figure.
MX_12W = _mx_model(
    "MX-12W",
    (360, 104),
    [
        *_mx_rows(
            model_number=360,
            baudrate=1,
            max_voltage_limit=160,
            pid=(8, 0, 8),
            punch=32,
            speed_rpm=0.916,
        ),
        _GOAL_ACCELERATION_ROW,
    ],
    470.0,
    0.2,
)

# e-manual: https://emanual.robotis.com/docs/en/dxl/mx/mx-28/ (protocol 1.0 control table; speed
# unit 0.114 rpm; stall torque 2.5 N·m and no-load speed 55 rpm at 12 V).
MX_28 = _mx_model(
    "MX-28",
    (29,),
    [
        *_mx_rows(
            model_number=29,
            baudrate=34,
            max_voltage_limit=160,
            pid=(0, 0, 32),
            punch=0,
            speed_rpm=0.114,
        ),
        _GOAL_ACCELERATION_ROW,
    ],
    55.0,
    2.5,
)

# e-manual: https://emanual.robotis.com/docs/en/dxl/mx/mx-64/ (protocol 1.0 control table, which
# lists a max voltage limit default of 240; stall torque 6.0 N·m and no-load speed 63 rpm at 12 V).
MX_64 = _mx_model(
    "MX-64",
    (310,),
    [
        *_mx_rows(
            model_number=310,
            baudrate=34,
            max_voltage_limit=240,
            pid=(0, 0, 32),
            punch=0,
            speed_rpm=0.114,
        ),
        *_TORQUE_CONTROL_ROWS,
        _GOAL_ACCELERATION_ROW,
    ],
    63.0,
    6.0,
)

# e-manual: https://emanual.robotis.com/docs/en/dxl/mx/mx-106/ (protocol 1.0 control table with
# Drive Mode at 10; stall torque 8.4 N·m and no-load speed 45 rpm at 12 V).
MX_106 = _mx_model(
    "MX-106",
    (320,),
    [
        *_mx_rows(
            model_number=320,
            baudrate=34,
            max_voltage_limit=160,
            pid=(0, 0, 32),
            punch=0,
            speed_rpm=0.114,
        ),
        _DRIVE_MODE_ROW,
        *_TORQUE_CONTROL_ROWS,
        _GOAL_ACCELERATION_ROW,
    ],
    45.0,
    8.4,
)
