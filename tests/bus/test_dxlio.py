"""pypot's DxlIO calls, as the documentation's scripts make them, on an emulated bus."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from poppy_core.bus import Dxl320IO, DxlIO
from poppy_core.emulator import build_bus_from_spec, ergo_jr_bus, serve_link
from poppy_core.errors import ArgumentError, RegisterError
from tests.helpers.waiting import eventually

BAUD = 1_000_000
# Every IO here talks to its motors on the in-process link (emu://): they answer in the
# writer's thread, never late on a busy machine, so the IOs keep pypot's timeout (50 ms, what
# each absent ID of a scan waits) instead of a pty emulator's loaded floor (up to 2 s each).
# (A pty between a bus and its emulator is the subject of tests/emulator and tests/interop.)


@pytest.fixture
def mx_port() -> Iterator[str]:
    """A protocol 1 bus with MX-28 motors 4, 5, 6 and an AX-12A 11, served in-process."""
    server = serve_link(build_bus_from_spec("MX-28:4-6,AX-12A:11", protocol=1, baudrate=BAUD))
    try:
        yield server.url
    finally:
        server.stop()


def test_the_documentation_script(mx_port: str) -> None:
    # "Low-level API" example: read, enable torque, go to 90°, disable torque.
    my_id = 11
    dxl_io = DxlIO(mx_port, baudrate=BAUD)
    pos = dxl_io.get_present_position([my_id])
    assert isinstance(pos, tuple) and len(pos) == 1
    dxl_io.enable_torque([my_id])
    assert dxl_io.is_torque_enabled([my_id]) == (True,)
    dxl_io.set_goal_position({my_id: 90})
    assert eventually(lambda: abs(dxl_io.get_present_position([my_id])[0] - 90) < 1.0)
    dxl_io.disable_torque([my_id])
    assert dxl_io.is_torque_enabled([my_id]) == (False,)
    dxl_io.close()


def test_scan_and_group_calls(mx_port: str) -> None:
    with DxlIO(mx_port, baudrate=BAUD) as dxl_io:
        assert dxl_io.scan(range(20)) == [4, 5, 6, 11]
        assert dxl_io.scan([0, 1, 2, 3, 4]) == [4]
        assert dxl_io.get_model([4, 11]) == ("MX-28", "AX-12A")
        dxl_io.enable_torque([4, 5, 6])
        dxl_io.set_goal_position({4: 0, 5: 10, 6: -25})
        assert eventually(
            lambda: all(
                abs(a - b) < 1.0
                for a, b in zip(dxl_io.get_present_position([4, 5, 6]), (0, 10, -25), strict=True)
            )
        )
        dxl_io.set_angle_limit({5: (-90, 90)})
        assert dxl_io.get_angle_limit([5]) == (pytest.approx((-90, 90), abs=0.2),)
        dxl_io.set_moving_speed({4: 100})
        assert dxl_io.get_moving_speed([4])[0] == pytest.approx(100, abs=1.0)


def test_change_id_as_the_documentation(mx_port: str) -> None:
    with DxlIO(mx_port, baudrate=BAUD) as dxl_io:
        found = dxl_io.scan([4])
        assert 4 in found
        dxl_io.set_return_delay_time({4: 0})
        dxl_io.change_id({4: 14})
        assert dxl_io.scan([4, 14]) == [14]


def test_dxl320io_speaks_protocol_2() -> None:
    server = serve_link(ergo_jr_bus())
    try:
        with Dxl320IO(server.url, baudrate=BAUD) as io:
            assert io.scan(range(8)) == [1, 2, 3, 4, 5, 6]
            assert io.get_model([1]) == ("XL-320",)
            io.switch_led_on([1])
            assert io.is_led_on([1]) == (True,)
            # The XL-320 keeps its mode in a register of its own (control_mode, 11).
            io.set_wheel_mode([2])
            assert io.get_control_mode([2, 3]) == ("wheel", "joint")
            io.set_joint_mode([2])
            assert io.get_control_mode([2]) == ("joint",)
    finally:
        server.stop()


def test_bad_calls_are_one_line(mx_port: str) -> None:
    with DxlIO(mx_port, baudrate=BAUD) as dxl_io:
        with pytest.raises(ArgumentError, match=r"list of IDs"):
            dxl_io.get_present_position(4)  # type: ignore[arg-type]
        with pytest.raises(ArgumentError, match=r"\{id: value\}"):
            dxl_io.set_goal_position([4, 0])  # type: ignore[arg-type]


# The documented calls of pypot's DxlIO (reference lines 4119-4440) on the emulated MX-28 and
# AX-12A bus above. Expected values: RECORDED from pypot 5.0.2's own DxlIO, run with the peers
# venv's python against `poppy emulate --motors MX-28:4-6,AX-12A:11` on a pty (2026-11-27), by
# bench/peers/pypot_dxlio_calls.py.
# pypot's degree scale divides by 4095 and 1023 where poppy's divides by the resolution (4096,
# 1024): pypot's angles are off by up to 0.3° (0.04° at the centre, 0.29° at an AX-12A's end).
PYPOT_ANSWERS = {
    "get_control_mode([4, 11])": ("joint", "joint"),
    "get_pid_gain([4])": ((4.0, 0.0, 0.0),),
    "get_pid_gain([4]) after set_pid_gain({4: (4, 2, 1)})": ((4.0, 1.953125, 1.0),),
    "get_compliance_margin([11])": ((1, 1),),
    "get_compliance_slope([11])": ((32, 32),),
    "get_goal_position_speed_load([4, 11])": ((0.04, 0.0, 100.0), (0.15, 0.0, 100.0)),
    "get_present_position_speed_load([4, 11])": ((0.04, 0.0, 0.0), (0.15, 0.0, 0.0)),
    "get_alarm_shutdown([4, 11])": (("Overload Error", "Overheating Error"),) * 2,
    "get_alarm_LED([4, 11])": (("Overload Error", "Overheating Error"),) * 2,
    "get_voltage_limit([4, 11])": ((6.0, 16.0), (6.0, 14.0)),
    "get_voltage_limit([4]) after set_voltage_limit({4: (7.0, 15.0)})": ((7.0, 15.0),),
    "get_highest_temperature_limit([4, 11])": (80.0, 70.0),
    "get_drive_mode([4])": (("normal", "master"),),
    "get_status_return_level([4, 11])": ("always", "always"),
    # pypot capped the speed to the register's top (1023 steps of 0.114 rpm on an MX-28).
    "get_moving_speed([4]) after set_moving_speed({4: 10000})": (699.732,),
    "get_control_table([4]) keys": (
        "model",
        "firmware",
        "id",
        "baudrate",
        "return delay time",
        "angle limit",
        "highest temperature limit",
        "voltage limit",
        "max torque",
        "status return level",
        "alarm LED",
        "alarm shutdown",
        "torque_enable",
        "LED",
        "pid gain",
        "goal position",
        "moving speed",
        "torque limit",
        "present position",
        "present speed",
        "present load",
        "present voltage",
        "present temperature",
        "moving",
    ),
}


def _close(answer: object, expected: object) -> bool:
    """Equal, numbers within 0.3 (the two libraries' degree scales differ by up to 0.29°)."""
    if isinstance(expected, tuple):
        return (
            isinstance(answer, tuple)
            and len(answer) == len(expected)
            and all(_close(a, e) for a, e in zip(answer, expected, strict=True))
        )
    if isinstance(expected, float):
        return isinstance(answer, int | float) and abs(answer - expected) <= 0.3
    return answer == expected


def test_wheel_and_joint_modes_as_pypot(mx_port: str) -> None:
    with DxlIO(mx_port, baudrate=BAUD) as dxl_io:
        assert dxl_io.get_control_mode([4, 11]) == PYPOT_ANSWERS["get_control_mode([4, 11])"]
        for motor_id in (5, 11):
            dxl_io.set_wheel_mode([motor_id])
            assert dxl_io.get_control_mode([motor_id]) == ("wheel",)
            dxl_io.set_joint_mode([motor_id])
            assert dxl_io.get_control_mode([motor_id]) == ("joint",)
        # Joint mode gives back the whole range (pypot: (-150, 150) on the AX-12A).
        assert _close(dxl_io.get_angle_limit([11]), ((-150.0, 150.0),))
        # In wheel mode the moving speed is the wheel's (the emulator's plant does not spin it).
        dxl_io.set_wheel_mode([5])
        dxl_io.set_moving_speed({5: -100})
        assert dxl_io.get_moving_speed([5]) == (pytest.approx(-100, abs=1.0),)
        dxl_io.set_control_mode({5: "joint"})
        assert dxl_io.get_control_mode([5]) == ("joint",)
        with pytest.raises(ArgumentError, match="joint' or 'wheel"):
            dxl_io.set_control_mode({5: "wheels"})


def test_gains_margins_and_grouped_registers_as_pypot(mx_port: str) -> None:
    with DxlIO(mx_port, baudrate=BAUD) as dxl_io:
        for call, answer in (
            ("get_pid_gain([4])", dxl_io.get_pid_gain([4])),
            ("get_compliance_margin([11])", dxl_io.get_compliance_margin([11])),
            ("get_compliance_slope([11])", dxl_io.get_compliance_slope([11])),
            ("get_goal_position_speed_load([4, 11])", dxl_io.get_goal_position_speed_load([4, 11])),
            (
                "get_present_position_speed_load([4, 11])",
                dxl_io.get_present_position_speed_load([4, 11]),
            ),
            ("get_alarm_shutdown([4, 11])", dxl_io.get_alarm_shutdown([4, 11])),
            ("get_alarm_LED([4, 11])", dxl_io.get_alarm_LED([4, 11])),
            ("get_voltage_limit([4, 11])", dxl_io.get_voltage_limit([4, 11])),
            (
                "get_highest_temperature_limit([4, 11])",
                dxl_io.get_highest_temperature_limit([4, 11]),
            ),
            ("get_drive_mode([4])", dxl_io.get_drive_mode([4])),
            ("get_status_return_level([4, 11])", dxl_io.get_status_return_level([4, 11])),
        ):
            assert _close(answer, PYPOT_ANSWERS[call]), (call, answer)
        dxl_io.set_pid_gain({4: (4, 2, 1)})
        assert _close(
            dxl_io.get_pid_gain([4]),
            PYPOT_ANSWERS["get_pid_gain([4]) after set_pid_gain({4: (4, 2, 1)})"],
        )
        dxl_io.set_voltage_limit({4: (7.0, 15.0)})
        assert _close(
            dxl_io.get_voltage_limit([4]),
            PYPOT_ANSWERS["get_voltage_limit([4]) after set_voltage_limit({4: (7.0, 15.0)})"],
        )
        dxl_io.set_goal_position_speed_load({4: (10.0, 50.0, 80.0)})
        goal, speed, load = dxl_io.get_goal_position_speed_load([4])[0]
        assert (goal, speed, load) == (
            pytest.approx(10.0, abs=0.1),
            pytest.approx(50.0, abs=1.0),
            pytest.approx(80.0, abs=0.2),
        )
        dxl_io.set_alarm_shutdown({11: ("Overload Error",)})
        assert dxl_io.get_alarm_shutdown([11]) == (("Overload Error",),)
        dxl_io.set_highest_temperature_limit({11: 65})
        assert dxl_io.get_highest_temperature_limit([11]) == (65.0,)
        with pytest.raises(ArgumentError, match="3 values"):
            dxl_io.set_pid_gain({4: 5})
        with pytest.raises(ArgumentError, match="unknown alarm"):
            dxl_io.set_alarm_LED({4: ("Overload", "Fire Error")})


def test_control_table_as_pypot(mx_port: str) -> None:
    with DxlIO(mx_port, baudrate=BAUD) as dxl_io:
        mx, ax = dxl_io.get_control_table([4, 11])
    assert tuple(mx) == PYPOT_ANSWERS["get_control_table([4]) keys"]
    assert mx["model"] == "MX-28" and mx["id"] == 4 and mx["status return level"] == "always"
    assert _close(mx["voltage limit"], (6.0, 16.0)) and mx["highest temperature limit"] == 80.0
    # The AX-12A has margins and slopes where the MX-28 has gains.
    assert ax["model"] == "AX-12A" and "pid gain" not in ax
    assert ax["compliance margin"] == (1, 1) and ax["compliance slope"] == (32, 32)


def test_speeds_positions_and_gains_beyond_their_range_are_capped_as_pypot(mx_port: str) -> None:
    with DxlIO(mx_port, baudrate=BAUD) as dxl_io:
        dxl_io.set_moving_speed({4: 10000})
        (speed,) = dxl_io.get_moving_speed([4])
        recorded = PYPOT_ANSWERS["get_moving_speed([4]) after set_moving_speed({4: 10000})"]
        assert speed == pytest.approx(recorded[0])
        dxl_io.set_wheel_mode([5])
        dxl_io.set_moving_speed({5: -10000})
        assert dxl_io.get_moving_speed([5]) == (pytest.approx(-speed),)
        dxl_io.set_goal_position({11: 400})
        assert dxl_io.get_goal_position([11]) == (pytest.approx(149.7, abs=0.1),)
        dxl_io.set_pid_gain({4: (100, 2, 1)})
        assert dxl_io.get_pid_gain([4])[0][0] == pytest.approx(254 / 8)
        for bad in (float("nan"), float("inf"), "fast"):
            with pytest.raises(RegisterError):
                dxl_io.set_moving_speed({4: bad})
        with pytest.raises(RegisterError):
            dxl_io.set_return_delay_time({4: 10000})  # never capped by pypot: refused
