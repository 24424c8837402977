"""A robot lets go of its buses and takes them back, and one built ``wait_for_motors`` starts
without its port or its motors' power and picks them up when they come (issue 26, items 1, 4)."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from poppy_core import from_profile
from poppy_core.bus import DxlBus
from poppy_core.emulator import VirtualBus, serve_pty
from poppy_core.errors import PortError, RobotClosedError, SetupError
from poppy_core.models import model_by_name
from poppy_core.robot import Robot, build_steps, load_profile
from poppy_core.robot.factory import virtual_buses
from tests.helpers.bus import loaded_reply_floor_s, robot_buses_wait_for_a_loaded_emulator
from tests.helpers.waiting import eventually

XL320 = model_by_name("XL-320")


@pytest.fixture(autouse=True)
def loaded_floor(monkeypatch: pytest.MonkeyPatch) -> None:
    """The emulator thread on a pty answers late on a busy machine: no motor is lost for that."""
    robot_buses_wait_for_a_loaded_emulator(monkeypatch)


def built_unplugged(monkeypatch: pytest.MonkeyPatch, **options: Any) -> Robot:
    """``from_profile("ergo-jr", **options)`` while every motor is unplugged: the build pings
    each one four times and none can answer, late or not, so those pings wait the product's own
    floor (the loaded one made it 6 x 4 x up to 2 s); the robot's buses wait the loaded floor
    again once built, for the motors that come."""
    loaded = build_steps.DxlBus
    monkeypatch.setattr(build_steps, "DxlBus", DxlBus)
    try:
        robot = from_profile("ergo-jr", sensors=False, **options)
    finally:
        monkeypatch.setattr(build_steps, "DxlBus", loaded)
    for bus in robot.buses.values():
        bus.min_timeout_s = loaded_reply_floor_s()
    return robot


@pytest.fixture
def virtual() -> VirtualBus:
    (bus,) = virtual_buses(load_profile("ergo-jr")).values()
    return bus


@pytest.fixture
def port(tmp_path: Path) -> str:
    return str(tmp_path / "ttyDXL")


@pytest.fixture
def on_pty(virtual: VirtualBus, port: str) -> Iterator[VirtualBus]:
    server = serve_pty(virtual, link=port)
    yield virtual
    server.stop()


def test_released_motors_are_compliant_and_their_port_free(on_pty: VirtualBus, port: str) -> None:
    with from_profile("ergo-jr", port=port, sensors=False) as robot:
        robot.m2.compliant = False
        robot.m2.goal_position = 30.0
        robot.m2.goto_position(-30.0, 5.0)
        with pytest.raises(PortError, match="busy"):
            DxlBus(port, 1_000_000, 2)
        assert robot.release_motors() == [port] and robot.released
        assert all(not m.online for m in robot.motors)
        assert not on_pty.motor(2).table.get("torque_enable")  # the servo itself let go
        with DxlBus(port, 1_000_000, 2) as other:  # another program opens the port
            assert other.read_register(2, XL320, "torque_enable") is False
            other.write_register(2, XL320, "led", "green")
        health = robot.health()["my_dxl_controller"]
        assert not health.connected and not health.ok
        robot.m2.goal_position = 10.0  # asked while released: never sent
        assert robot.take_motors() == [port] and not robot.released
        assert all(m.online for m in robot.motors) and robot.m2.compliant
        assert eventually(lambda: robot.health()["my_dxl_controller"].ok)
        assert not on_pty.motor(2).table.get("torque_enable")


def test_take_refused_while_the_port_is_held_then_granted(on_pty: VirtualBus, port: str) -> None:
    with from_profile("ergo-jr", port=port, sensors=False) as robot:
        robot.release_motors()
        with DxlBus(port, 1_000_000, 2), pytest.raises(PortError, match="busy"):
            robot.take_motors()
        assert robot.released
        robot.take_motors()
        assert not robot.released and all(m.online for m in robot.motors)


def test_a_closed_robot_cannot_be_released(on_pty: VirtualBus, port: str) -> None:
    robot = from_profile("ergo-jr", port=port, sensors=False)
    robot.close()
    with pytest.raises(RobotClosedError):
        robot.release_motors()
    with pytest.raises(RobotClosedError):
        robot.take_motors()


def test_a_missing_port_is_refused_unless_waited_for(port: str, virtual: VirtualBus) -> None:
    with pytest.raises(PortError, match="no such port"):
        from_profile("ergo-jr", port=port, sensors=False)
    with from_profile("ergo-jr", port=port, sensors=False, wait_for_motors=True) as robot:
        health = robot.health()["my_dxl_controller"]
        assert not health.connected and health.offline == [m.name for m in robot.motors]
        virtual.motor(4).set_state(-42.0, 0.0, 0.0, False)
        with serve_pty(virtual, link=port):
            assert eventually(lambda: all(m.online for m in robot.motors))
            assert robot.m4.present_position == pytest.approx(-42.0, abs=0.5)
            robot.m4.compliant = False
            robot.m4.goal_position = 15.0
            assert eventually(lambda: abs(robot.m4.present_position - 15.0) < 3.0)


def test_motors_without_power_are_waited_for(
    on_pty: VirtualBus, port: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    for motor in on_pty.motors:
        on_pty.unplug(motor.id)
    with pytest.raises(SetupError, match="missing motors"):
        built_unplugged(monkeypatch, port=port)
    with built_unplugged(monkeypatch, port=port, wait_for_motors=True) as robot:
        assert not any(m.online for m in robot.motors)
        on_pty.motor(1).table.set("torque_enable", 1)  # stiff already (another program)
        for motor in on_pty.motors:  # the power comes on
            on_pty.plug(motor.id)
        assert eventually(lambda: all(m.online for m in robot.motors))
        # its state read when it first answered, not the defaults of a motor never seen
        assert not robot.m1.compliant and robot.m2.compliant


def test_an_auto_port_with_no_motors_waits_on_the_port_searched(
    on_pty: VirtualBus, port: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    for motor in on_pty.motors:
        on_pty.unplug(motor.id)
    with built_unplugged(monkeypatch, port="auto", wait_for_motors=True, ports=[port]) as robot:
        assert robot.ports == [port] and not any(m.online for m in robot.motors)
        for motor in on_pty.motors:
            on_pty.plug(motor.id)
        assert eventually(lambda: all(m.online for m in robot.motors))
    with pytest.raises(SetupError, match="no free serial port to search"):
        from_profile("ergo-jr", port="auto", sensors=False, wait_for_motors=True, ports=[])
