"""AX-12A and AX-18A control tables (protocol 1.0)."""

from __future__ import annotations

from poppy_core.models.converters import (
    BOOL,
    LOAD_PERCENT,
    RAW,
    RETURN_DELAY,
    TEMPERATURE,
    TORQUE_PERCENT,
    VOLTAGE,
    Baudrate,
    DirectionBit,
    position,
)
from poppy_core.models.model import ServoModel, aliases_for
from poppy_core.models.register import Row, build_table

# e-manual (AX-12A, "Baud Rate (4)"): bps = 2,000,000 / (code + 1); the listed codes with the
# nominal rates a PC opens its port at (code 16 → 117,647 bps, nominal 115,200: -2.1 %). The AX
# goes from 7,843 bps (code 254) to 1 Mbps (code 1): code 0 (2 Mbps) is refused.
PROTOCOL1_LISTED_BAUDRATES: dict[int, int] = {
    1: 1_000_000,
    3: 500_000,
    4: 400_000,
    7: 250_000,
    9: 200_000,
    16: 115_200,
    34: 57_600,
    103: 19_200,
    207: 9_600,
}
PROTOCOL1_CLOCK_BPS = 2_000_000
PROTOCOL1_RAM_START = 24

AX_POSITION = position(300.0, 1024)
# e-manual: Moving Speed / Present Speed unit "about 0.111 rpm" (joint mode); bit 10 = CW.
AX_SPEED = DirectionBit(0.111 * 6.0, "deg/s")
AX_BAUDRATE = Baudrate(
    tuple(PROTOCOL1_LISTED_BAUDRATES.items()), clock_bps=PROTOCOL1_CLOCK_BPS, max_code=254
)


def _ax_rows(model_number: int, temperature_limit: int, max_torque: int) -> list[Row]:
    return [
        # name, address, size, access, default, min_raw, max_raw, conversion
        ("model_number", 0, 2, "R", model_number, 0, 0xFFFF, RAW),
        ("firmware", 2, 1, "R", None, 0, 0xFF, RAW),
        ("id", 3, 1, "RW", 1, 0, 253, RAW),
        ("baudrate", 4, 1, "RW", 1, 1, 254, AX_BAUDRATE),
        ("return_delay_time", 5, 1, "RW", 250, 0, 254, RETURN_DELAY),
        ("cw_angle_limit", 6, 2, "RW", 0, 0, 1023, AX_POSITION),
        ("ccw_angle_limit", 8, 2, "RW", 1023, 0, 1023, AX_POSITION),
        ("temperature_limit", 11, 1, "RW", temperature_limit, 0, 150, TEMPERATURE),
        ("min_voltage_limit", 12, 1, "RW", 60, 50, 250, VOLTAGE),
        ("max_voltage_limit", 13, 1, "RW", 140, 50, 250, VOLTAGE),
        ("max_torque", 14, 2, "RW", max_torque, 0, 1023, TORQUE_PERCENT),
        ("status_return_level", 16, 1, "RW", 2, 0, 2, RAW),
        ("alarm_led", 17, 1, "RW", 36, 0, 127, RAW),
        ("shutdown", 18, 1, "RW", 36, 0, 127, RAW),
        ("torque_enable", 24, 1, "RW", 0, 0, 1, BOOL),
        ("led", 25, 1, "RW", 0, 0, 1, BOOL),
        # Compliance margin in position ticks, slope as the e-manual's 7-step value: kept raw.
        ("cw_compliance_margin", 26, 1, "RW", 1, 0, 255, RAW),
        ("ccw_compliance_margin", 27, 1, "RW", 1, 0, 255, RAW),
        ("cw_compliance_slope", 28, 1, "RW", 32, 0, 254, RAW),
        ("ccw_compliance_slope", 29, 1, "RW", 32, 0, 254, RAW),
        ("goal_position", 30, 2, "RW", None, 0, 1023, AX_POSITION),
        ("moving_speed", 32, 2, "RW", None, 0, 2047, AX_SPEED),
        # Torque Limit starts as Max Torque (e-manual: "ADD 14&15").
        ("torque_limit", 34, 2, "RW", max_torque, 0, 1023, TORQUE_PERCENT),
        ("present_position", 36, 2, "R", None, 0, 1023, AX_POSITION),
        ("present_speed", 38, 2, "R", None, 0, 2047, AX_SPEED),
        ("present_load", 40, 2, "R", None, 0, 2047, LOAD_PERCENT),
        ("present_voltage", 42, 1, "R", None, 0, 255, VOLTAGE),
        ("present_temperature", 43, 1, "R", None, 0, 255, TEMPERATURE),
        ("registered", 44, 1, "R", 0, 0, 1, BOOL),
        ("moving", 46, 1, "R", 0, 0, 1, BOOL),
        ("lock", 47, 1, "RW", 0, 0, 1, BOOL),
        ("punch", 48, 2, "RW", 32, 0, 1023, RAW),
    ]


def _ax_model(
    name: str,
    model_number: int,
    temperature_limit: int,
    max_torque: int,
    no_load_rpm: float,
    stall_torque_nm: float,
) -> ServoModel:
    registers = build_table(
        _ax_rows(model_number, temperature_limit, max_torque), PROTOCOL1_RAM_START
    )
    return ServoModel(
        name=name,
        model_numbers=(model_number,),
        protocol=1,
        registers=registers,
        aliases=aliases_for(registers, xseries=False),
        position_range_deg=300.0,
        resolution=1024,
        no_load_speed_dps=no_load_rpm * 6.0,
        stall_torque_nm=stall_torque_nm,
        baudrates=PROTOCOL1_LISTED_BAUDRATES,
        has_torque_limit=True,
    )


# e-manual: https://emanual.robotis.com/docs/en/dxl/ax/ax-12a/ (control table; specifications:
# stall torque 1.5 N·m at 12 V, no-load speed 59 rpm at 12 V).
AX_12A = _ax_model("AX-12A", 12, 70, 1023, 59.0, 1.5)

# e-manual: https://emanual.robotis.com/docs/en/dxl/ax/ax-18a/ (control table: temperature limit 75,
# max torque 983; specifications: stall torque 1.8 N·m at 12 V, no-load speed 97 rpm at 12 V).
AX_18A = _ax_model("AX-18A", 18, 75, 983, 97.0, 1.8)
