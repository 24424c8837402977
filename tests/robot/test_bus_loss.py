"""A lost bus says so (one warning, motors offline, health), is reopened, and its motors resume."""

from __future__ import annotations

import logging
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from poppy_core import from_profile
from poppy_core.emulator import Endpoint, VirtualBus, serve_link, serve_pty, serve_tcp
from poppy_core.robot import Robot, load_profile
from poppy_core.robot.factory import virtual_buses
from tests.helpers.bus import robot_buses_wait_for_a_loaded_emulator
from tests.helpers.waiting import eventually, scaled


def ergo_jr_virtual() -> VirtualBus:
    (bus,) = virtual_buses(load_profile("ergo-jr")).values()
    return bus


@pytest.fixture(autouse=True)
def loaded_floor(monkeypatch: pytest.MonkeyPatch) -> None:
    """The emulator threads here answer late on a busy machine: no motor is lost for that."""
    robot_buses_wait_for_a_loaded_emulator(monkeypatch)


@pytest.fixture(params=["tcp", "pty link", "in-process"])
def served(request: pytest.FixtureRequest, tmp_path: Path) -> Iterator[tuple[Endpoint, str]]:
    """An Ergo Jr bus served on TCP, on a pty through a symlink (as /dev/serial/by-id), or
    linked in this process (``emu://``)."""
    virtual = ergo_jr_virtual()
    server: Endpoint
    if request.param == "tcp":
        server = serve_tcp(virtual)
        port = server.url
    elif request.param == "in-process":
        server = serve_link(virtual)
        port = server.url
    else:
        port = str(tmp_path / "ttyDXL")
        server = serve_pty(virtual, link=port)
    yield server, port
    server.stop()


def sync_warnings(caplog: pytest.LogCaptureFixture, text: str) -> list[str]:
    records = [r for r in caplog.records if r.name == "poppy_core.robot.sync"]
    warnings = [r.getMessage() for r in records if r.levelno == logging.WARNING]
    return [message for message in warnings if text in message]


def test_health_of_a_healthy_robot(served: tuple[Endpoint, str]) -> None:
    _, port = served
    with from_profile("ergo-jr", port=port, sensors=False) as robot:
        assert eventually(lambda: robot.health()["my_dxl_controller"].loop_hz["present"] > 0)
        health = robot.health()["my_dxl_controller"]
        assert health.connected and health.running and health.ok
        assert health.offline == [] and health.losses == 0 and health.down_s == 0
        assert health.target_hz["present"] == 50.0
        data = health.as_dict()
        assert data["ok"] is True and data["port"] == port


def test_a_lost_bus_is_loud_then_comes_back(
    served: tuple[Endpoint, str], caplog: pytest.LogCaptureFixture
) -> None:
    server, port = served
    caplog.set_level(logging.WARNING, logger="poppy_core.robot.sync")
    with from_profile("ergo-jr", port=port, sensors=False) as robot:
        assert eventually(lambda: all(m.online for m in robot.motors))
        server.lose(1.0)
        assert eventually(lambda: not any(m.online for m in robot.motors))
        health = robot.health()["my_dxl_controller"]
        assert not health.connected and health.losses == 1
        assert sorted(health.offline) == sorted(m.name for m in robot.motors)
        assert eventually(lambda: robot.health()["my_dxl_controller"].loop_hz["present"] == 0)
        # back: reopened by the sync thread, motors answer again, writes reach them
        assert eventually(lambda: all(m.online for m in robot.motors))
        assert robot.health()["my_dxl_controller"].connected
        robot.m3.compliant = False
        robot.m3.goal_position = 20.0
        motor = server.bus.motor(robot.m3.id)
        wanted = robot.m3.to_motor(20.0)
        assert eventually(
            lambda: motor.torque_enabled and abs(motor.goal_position_deg - wanted) < 1
        )
        assert eventually(lambda: abs(robot.m3.present_position - 20.0) < 2)
    # the bus named by what it is (its port), not by pypot's placeholder controller name
    shown = port if "://" in port else port.rsplit("/", 1)[-1]  # ttyDXL, emu://1
    assert len(sync_warnings(caplog, f"bus {shown}: lost {port} ")) == 1
    assert not any("my_dxl_controller" in r.getMessage() for r in caplog.records)
    assert len(sync_warnings(caplog, "motors are offline")) == 1
    assert len(sync_warnings(caplog, " is back after ")) == 1
    assert not any("stopped answering" in r.getMessage() for r in caplog.records)


def test_a_bus_that_never_comes_back_is_retried_quietly(
    caplog: pytest.LogCaptureFixture,
) -> None:
    caplog.set_level(logging.WARNING, logger="poppy_core.robot.sync")
    server = serve_tcp(ergo_jr_virtual())
    robot: Robot = from_profile("ergo-jr", port=server.url, sensors=False)
    try:
        server.stop()  # gone for good
        assert eventually(lambda: not robot.health()["my_dxl_controller"].connected)
        time.sleep(1.5)  # a few reopen attempts
        assert robot.health()["my_dxl_controller"].running
        assert len(sync_warnings(caplog, ": lost ")) == 1
        started = time.monotonic()
    finally:
        robot.close()
    assert time.monotonic() - started < scaled(5.0)
