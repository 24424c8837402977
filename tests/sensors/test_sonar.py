"""SonarSensor: an SRF-02 on I2C, through a fake SMBus that answers as the module does.

The module's facts (Devantech's SRF02 I2C-mode technical specification): a command is written
to register 0 (0x51: range in centimetres); for up to 65 ms it does not answer on the bus; then
registers 2 and 3 hold the range's high and low bytes; register 0 reads its software revision.
"""

from __future__ import annotations

import logging
import threading
import time

import pytest

from poppy_core import from_config
from poppy_core.robot import RobotConfig, load_profile
from poppy_core.sensors.sonar import SonarSensor
from tests.helpers.sensor_rest import rest
from tests.helpers.waiting import eventually

NOT_ANSWERING = 121  # EREMOTEIO: the I2C adapter saw no acknowledge


class FakeSrf02Bus:
    """An I2C bus with one SRF-02 at ``address`` measuring ``cm``."""

    def __init__(self, address: int = 0x70, cm: int = 123) -> None:
        self.address = address
        self.cm = cm
        self.present = True
        self.commands: list[int] = []
        self.closed = 0
        self._range = 0
        self._busy_until = 0.0
        self._lock = threading.Lock()

    def _answer(self, address: int) -> None:
        if not self.present or address != self.address or time.monotonic() < self._busy_until:
            raise OSError(NOT_ANSWERING, "Remote I/O error")

    def write_byte_data(self, address: int, register: int, value: int) -> None:
        with self._lock:
            self._answer(address)
            if register == 0:
                self.commands.append(value)
                if value == 0x51:
                    self._range = self.cm
                    self._busy_until = time.monotonic() + 0.065

    def read_byte_data(self, address: int, register: int) -> int:
        with self._lock:
            self._answer(address)
            return {0: 6, 1: 0x80, 2: self._range >> 8, 3: self._range & 0xFF}.get(register, 0)

    def close(self) -> None:
        self.closed += 1


def test_distance_is_the_range_in_metres_through_the_modules_registers() -> None:
    bus = FakeSrf02Bus(address=0x71, cm=300)  # 300 cm: 0x01 in register 2, 0x2C in 3
    opened: list[int] = []

    def opener(number: int) -> FakeSrf02Bus:
        opened.append(number)
        return bus

    with SonarSensor("sonar", 1, 0x71, 50.0, opener=opener) as sensor:
        assert sensor.distance == pytest.approx(3.0)
        assert opened == [1] and set(bus.commands) == {0x51}
        bus.cm = 42  # the median of the last five follows once most of them are new
        assert eventually(lambda: sensor.distance == pytest.approx(0.42), timeout_s=10)
        assert sensor.read("distance") == pytest.approx(0.42)
        health = sensor.health()
        assert health.connected and health.errors == 0 and health.kind == "SonarSensor"
    assert bus.closed == 1


def test_a_module_that_stops_answering_is_lost_once_then_resumes(
    caplog: pytest.LogCaptureFixture,
) -> None:
    bus = FakeSrf02Bus(cm=80)
    with caplog.at_level(logging.WARNING), SonarSensor("sonar", 1, opener=lambda n: bus) as sensor:
        assert sensor.distance == pytest.approx(0.8)
        bus.present = False
        assert eventually(lambda: not sensor.health().connected)
        lost = sensor.health()
        assert lost.losses == 1 and "address 0x70" in lost.last_error
        assert sensor.distance == pytest.approx(0.8)  # the last value stays readable
        bus.cm = 150
        bus.present = True
        assert eventually(lambda: sensor.distance == pytest.approx(1.5), timeout_s=15)
        assert sensor.health().connected and sensor.health().losses == 1
    messages = [r.getMessage() for r in caplog.records if r.levelno == logging.WARNING]
    assert len([m for m in messages if "SonarSensor sonar lost" in m]) == 1
    assert len([m for m in messages if "SonarSensor sonar is back" in m]) == 1


def test_a_pypot_config_entry_is_robot_dot_name(monkeypatch: pytest.MonkeyPatch) -> None:
    smbus2 = pytest.importorskip("smbus2")
    bus = FakeSrf02Bus(address=112, cm=57)
    opened: list[int] = []
    monkeypatch.setattr(smbus2, "SMBus", lambda number: opened.append(number) or bus)
    data = load_profile("ergo-jr").to_pypot_dict()
    data["sensors"] = {"sonar": {"type": "SonarSensor", "i2c_pin": 3, "address": 112}}
    with from_config(RobotConfig.from_dict(data), sim=True) as robot:
        assert robot.sonar.distance == pytest.approx(0.57)
        assert opened == [3] and robot.sensor_health()["sonar"].connected
        with rest(robot) as client:
            assert client.get("/sensors/sonar/registers/list.json").json() == {
                "registers": ["distance"]
            }
            value = client.get("/sensors/sonar/registers/distance/value.json").json()
            assert value == {"distance": pytest.approx(0.57)}
    assert robot.sonar.closed
