"""pypot's DxlIO calls, as the documentation's scripts make them, on an emulated bus."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from poppy_core.bus import Dxl320IO, DxlIO
from poppy_core.emulator import build_bus_from_spec, ergo_jr_bus, serve_pty
from poppy_core.errors import ArgumentError
from tests.helpers.waiting import eventually

BAUD = 1_000_000


@pytest.fixture
def mx_port() -> Iterator[str]:
    """A protocol 1 bus with MX-28 motors 4, 5, 6 and an AX-12A 11, served on a pty."""
    server = serve_pty(build_bus_from_spec("MX-28:4-6,AX-12A:11", protocol=1, baudrate=BAUD))
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
        assert eventually(lambda: all(
            abs(a - b) < 1.0
            for a, b in zip(dxl_io.get_present_position([4, 5, 6]), (0, 10, -25), strict=True)
        ))  # fmt: skip
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
    server = serve_pty(ergo_jr_bus())
    try:
        with Dxl320IO(server.url, baudrate=BAUD) as io:
            assert io.scan(range(8)) == [1, 2, 3, 4, 5, 6]
            assert io.get_model([1]) == ("XL-320",)
            io.switch_led_on([1])
            assert io.is_led_on([1]) == (True,)
    finally:
        server.stop()


def test_bad_calls_are_one_line(mx_port: str) -> None:
    with DxlIO(mx_port, baudrate=BAUD) as dxl_io:
        with pytest.raises(ArgumentError, match=r"list of IDs"):
            dxl_io.get_present_position(4)  # type: ignore[arg-type]
        with pytest.raises(ArgumentError, match=r"\{id: value\}"):
            dxl_io.set_goal_position([4, 0])  # type: ignore[arg-type]
