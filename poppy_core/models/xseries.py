"""X-series control tables (protocol 2.0): XL430-W250, XM430-W350, XL330-M288.

The Indirect Address / Indirect Data areas (168 onwards) are left out: poppy does not use them,
so ``table_size`` ends after the last status register (146 or 147).
"""

from __future__ import annotations

from dataclasses import dataclass

from poppy_core.models.converters import (
    BOOL,
    MILLISECONDS,
    RAW,
    RETURN_DELAY,
    TEMPERATURE,
    VOLTAGE,
    Baudrate,
    Linear,
    gain,
    position,
    rpm,
)
from poppy_core.models.model import ServoModel, aliases_for
from poppy_core.models.register import Row, build_table

# e-manual (X-series "Baud Rate (8)", control_table_baudrate_2).
X_BAUDRATES: dict[int, int] = {
    0: 9_600,
    1: 57_600,
    2: 115_200,
    3: 1_000_000,
    4: 2_000_000,
    5: 3_000_000,
    6: 4_000_000,
    7: 4_500_000,
}
X_RAM_START = 64
INT16 = (-(1 << 15), (1 << 15) - 1)
INT32 = (-(1 << 31), (1 << 31) - 1)
# Goal/present position span in Extended Position Control Mode (e-manual: ±256 revolutions).
EXTENDED_POSITION = (-1_048_575, 1_048_575)

X_POSITION = position(360.0, 4096)
X_TICKS_DEG = Linear(360.0 / 4096, "deg")  # Homing Offset: ticks without the centring offset
X_VELOCITY = rpm(0.229)  # e-manual: 0.229 rev/min per unit
X_PWM = Linear(0.113, "%")  # e-manual: 0.113 % per unit (885 = 100 %)
# e-manual: Profile Acceleration unit 214.577 rev/min² = 21.4577 °/s² (time-based profile when
# Drive Mode bit 2 is set: then the raw value is milliseconds).
X_ACCELERATION = Linear(214.577 * 360.0 / 3600.0, "deg/s²")
# e-manual (Position PID / Velocity PI / Feedforward gains): KPP = raw/128, KPI = raw/65536,
# KPD = raw/16, KVP = raw/128, KVI = raw/65536, KFF = raw/4.
GAIN_ROWS_SCALES = {
    "velocity_i_gain": 1 / 65536,
    "velocity_p_gain": 1 / 128,
    "position_d_gain": 1 / 16,
    "position_i_gain": 1 / 65536,
    "position_p_gain": 1 / 128,
}


@dataclass(frozen=True)
class XSpec:
    """What differs between the X-series tables (all values raw, from the e-manual pages)."""

    model_number: int
    id_max: int
    baud_max: int
    drive_mode_max: int
    protocol_type_range: tuple[int, int]
    temperature_limit: int
    max_voltage_limit: int
    min_voltage_limit: int
    voltage_range: tuple[int, int]
    velocity_limit: int
    velocity_max: int
    gains: tuple[int, int, int, int, int]  # velocity I, velocity P, position D, I, P
    shutdown: int
    current_unit_ma: float | None  # None: Present Load (%) instead of current registers
    current_limit: int = 0
    startup_configuration: bool = True
    backup_ready: bool = True
    pwm_slope: bool = False


def _x_rows(spec: XSpec) -> list[Row]:
    vlow, vhigh = spec.voltage_range
    rows: list[Row] = [
        # name, address, size, access, default, min_raw, max_raw, conversion
        ("model_number", 0, 2, "R", spec.model_number, 0, 0xFFFF, RAW),
        ("model_information", 2, 4, "R", None, 0, 0xFFFFFFFF, RAW),
        ("firmware", 6, 1, "R", None, 0, 0xFF, RAW),
        ("id", 7, 1, "RW", 1, 0, spec.id_max, RAW),
        ("baudrate", 8, 1, "RW", 1, 0, spec.baud_max, _baudrate(spec.baud_max)),
        ("return_delay_time", 9, 1, "RW", 250, 0, 254, RETURN_DELAY),
        ("drive_mode", 10, 1, "RW", 0, 0, spec.drive_mode_max, RAW),
        ("operating_mode", 11, 1, "RW", 3, 0, 16, RAW),
        # 255 (the default) disables the secondary ID.
        ("secondary_id", 12, 1, "RW", 255, 0, 255, RAW),
        ("protocol_type", 13, 1, "RW", 2, *spec.protocol_type_range, RAW),
        ("homing_offset", 20, 4, "RW", 0, -1_044_479, 1_044_479, X_TICKS_DEG),
        ("moving_threshold", 24, 4, "RW", 10, 0, 1023, X_VELOCITY),
        ("temperature_limit", 31, 1, "RW", spec.temperature_limit, 0, 100, TEMPERATURE),
        ("max_voltage_limit", 32, 2, "RW", spec.max_voltage_limit, vlow, vhigh, VOLTAGE),
        ("min_voltage_limit", 34, 2, "RW", spec.min_voltage_limit, vlow, vhigh, VOLTAGE),
        ("pwm_limit", 36, 2, "RW", 885, 0, 885, X_PWM),
        ("velocity_limit", 44, 4, "RW", spec.velocity_limit, 0, spec.velocity_max, X_VELOCITY),
        ("max_position_limit", 48, 4, "RW", 4095, 0, 4095, X_POSITION),
        ("min_position_limit", 52, 4, "RW", 0, 0, 4095, X_POSITION),
        ("shutdown", 63, 1, "RW", spec.shutdown, 0, 255, RAW),
        ("torque_enable", 64, 1, "RW", 0, 0, 1, BOOL),
        ("led", 65, 1, "RW", 0, 0, 1, BOOL),
        ("status_return_level", 68, 1, "RW", 2, 0, 2, RAW),
        ("registered", 69, 1, "R", 0, 0, 1, BOOL),
        ("hardware_error_status", 70, 1, "R", 0, 0, 255, RAW),
        *[
            (name, address, 2, "RW", default, 0, 16383, gain(GAIN_ROWS_SCALES[name]))
            for (name, address), default in zip(
                (
                    ("velocity_i_gain", 76),
                    ("velocity_p_gain", 78),
                    ("position_d_gain", 80),
                    ("position_i_gain", 82),
                    ("position_p_gain", 84),
                ),
                spec.gains,
                strict=True,
            )
        ],
        ("feedforward_2nd_gain", 88, 2, "RW", 0, 0, 16383, gain(1 / 4)),
        ("feedforward_1st_gain", 90, 2, "RW", 0, 0, 16383, gain(1 / 4)),
        # e-manual: Bus Watchdog unit 20 ms, 0 disables; kept raw.
        ("bus_watchdog", 98, 1, "RW", 0, 0, 127, RAW),
        ("goal_pwm", 100, 2, "RW", None, -885, 885, X_PWM),
        ("goal_velocity", 104, 4, "RW", None, -spec.velocity_max, spec.velocity_max, X_VELOCITY),
        ("profile_acceleration", 108, 4, "RW", 0, 0, 32767, X_ACCELERATION),
        # Profile Velocity 0 means "no velocity limit" (like protocol-1 Moving Speed 0).
        ("profile_velocity", 112, 4, "RW", 0, 0, 32767, X_VELOCITY),
        ("goal_position", 116, 4, "RW", None, *EXTENDED_POSITION, X_POSITION),
        ("realtime_tick", 120, 2, "R", None, 0, 32767, MILLISECONDS),
        ("moving", 122, 1, "R", 0, 0, 1, BOOL),
        ("moving_status", 123, 1, "R", 0, 0, 255, RAW),
        ("present_pwm", 124, 2, "R", None, *INT16, X_PWM),
        ("present_velocity", 128, 4, "R", None, *INT32, X_VELOCITY),
        ("present_position", 132, 4, "R", None, *INT32, X_POSITION),
        ("velocity_trajectory", 136, 4, "R", None, *INT32, X_VELOCITY),
        ("position_trajectory", 140, 4, "R", None, *INT32, X_POSITION),
        ("present_input_voltage", 144, 2, "R", None, 0, 0xFFFF, VOLTAGE),
        ("present_temperature", 146, 1, "R", None, 0, 255, TEMPERATURE),
    ]
    if spec.current_unit_ma is None:
        # e-manual (XL430-W250): Present Load, 0.1 % signed, -1000..1000.
        rows.append(("present_load", 126, 2, "R", None, -1000, 1000, Linear(0.1, "%")))
    else:
        current = Linear(spec.current_unit_ma, "mA")
        limit = spec.current_limit
        rows += [
            ("current_limit", 38, 2, "RW", limit, 0, limit, current),
            ("goal_current", 102, 2, "RW", None, -limit, limit, current),
            ("present_current", 126, 2, "R", None, *INT16, current),
        ]
    if spec.startup_configuration:
        rows.append(("startup_configuration", 60, 1, "RW", 0, 0, 3, RAW))
    if spec.pwm_slope:
        rows.append(("pwm_slope", 62, 1, "RW", 140, 1, 255, Linear(1.977, "mV/ms")))
    if spec.backup_ready:
        rows.append(("backup_ready", 147, 1, "R", 0, 0, 1, BOOL))
    return sorted(rows, key=lambda row: row[1])


def _baudrate(max_code: int) -> Baudrate:
    return Baudrate(tuple((code, bps) for code, bps in X_BAUDRATES.items() if code <= max_code))


def _x_model(name: str, spec: XSpec, no_load_rpm: float, stall_torque_nm: float) -> ServoModel:
    registers = build_table(_x_rows(spec), X_RAM_START)
    return ServoModel(
        name=name,
        model_numbers=(spec.model_number,),
        protocol=2,
        registers=registers,
        aliases=aliases_for(registers, xseries=True),
        position_range_deg=360.0,
        resolution=4096,
        no_load_speed_dps=no_load_rpm * 6.0,
        stall_torque_nm=stall_torque_nm,
        baudrates={c: b for c, b in X_BAUDRATES.items() if c <= spec.baud_max},
        has_torque_limit=False,
    )


# e-manual: https://emanual.robotis.com/docs/en/dxl/x/xl430-w250/ (control table; specifications:
# stall torque 1.4 N·m and no-load speed 57 rpm at the recommended 11.1 V).
XL430_W250 = _x_model(
    "XL430-W250",
    XSpec(
        model_number=1060,
        id_max=252,
        baud_max=7,
        drive_mode_max=13,
        protocol_type_range=(1, 2),
        temperature_limit=72,
        max_voltage_limit=140,
        min_voltage_limit=60,
        voltage_range=(60, 140),
        velocity_limit=265,
        velocity_max=1023,
        gains=(1000, 100, 4000, 0, 640),
        shutdown=52,
        current_unit_ma=None,
    ),
    57.0,
    1.4,
)

# e-manual: https://emanual.robotis.com/docs/en/dxl/x/xm430-w350/ (control table; the page gives the
# voltage-limit range as 110~300 next to defaults 95/160, so 95..160 is used; specifications:
# stall torque 4.1 N·m and no-load speed 46 rpm at the recommended 12 V).
XM430_W350 = _x_model(
    "XM430-W350",
    XSpec(
        model_number=1020,
        id_max=253,
        baud_max=7,
        drive_mode_max=1,
        protocol_type_range=(1, 2),
        temperature_limit=80,
        max_voltage_limit=160,
        min_voltage_limit=95,
        voltage_range=(95, 160),
        velocity_limit=200,
        velocity_max=1023,
        gains=(1920, 100, 0, 0, 800),
        shutdown=52,
        current_unit_ma=2.69,
        current_limit=1193,
        startup_configuration=False,
        backup_ready=False,
    ),
    46.0,
    4.1,
)

# e-manual: https://emanual.robotis.com/docs/en/dxl/x/xl330-m288/ (control table; specifications:
# stall torque 0.52 N·m and no-load speed 103 rpm at the recommended 5.0 V; up to 4 Mbps).
XL330_M288 = _x_model(
    "XL330-M288",
    XSpec(
        model_number=1200,
        id_max=252,
        baud_max=6,
        drive_mode_max=5,
        protocol_type_range=(2, 22),
        temperature_limit=70,
        max_voltage_limit=70,
        min_voltage_limit=35,
        voltage_range=(31, 70),
        velocity_limit=445,
        velocity_max=2047,
        gains=(1600, 180, 0, 0, 400),
        shutdown=53,
        current_unit_ma=1.0,
        current_limit=1750,
        pwm_slope=True,
    ),
    103.0,
    0.52,
)
