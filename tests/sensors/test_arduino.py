"""ArduinoSensor: JSON lines from a board through a real pseudo-terminal, as a board's USB serial
port sends them; a broken line and an unplugged board are said once, shown in health, and the
sensor resumes when the board is back (the port's link re-pointed, as udev's by-id links are)."""

from __future__ import annotations

import logging
import os
import tty
from collections.abc import Iterator
from pathlib import Path

import pytest

from poppy_core import from_config
from poppy_core.errors import SensorError
from poppy_core.robot import RobotConfig, load_profile
from poppy_core.sensors.arduino import ArduinoSensor
from tests.helpers.sensor_rest import rest
from tests.helpers.waiting import eventually


class Board:
    """The board's side of a pseudo-terminal; ``link`` is the port the sensor opens."""

    def __init__(self, link: Path) -> None:
        self.link = link
        self.plug()

    def plug(self) -> None:
        self.master, self.slave = os.openpty()
        tty.setraw(self.slave)
        if self.link.is_symlink():
            self.link.unlink()
        self.link.symlink_to(os.ttyname(self.slave))

    def send(self, data: bytes) -> None:
        os.write(self.master, data)

    def unplug(self) -> None:
        os.close(self.master)
        os.close(self.slave)
        self.master = self.slave = -1

    def close(self) -> None:
        if self.master >= 0:
            self.unplug()


def arrives(sensor: ArduinoSensor, board: Board, line: bytes, expected: object) -> bool:
    """The board prints ``line`` over and over, as a board does, until the sensor shows it
    (pyserial drops what arrived before it opened the port, as it does with a real board)."""
    sensor.start()

    def shown() -> bool:
        board.send(line)
        return sensor.health().age_s is not None and sensor.sensor_dict == expected

    return eventually(shown, timeout_s=10, interval_s=0.02)


@pytest.fixture
def board(tmp_path: Path) -> Iterator[Board]:
    made = Board(tmp_path / "ttyACM0")
    yield made
    made.close()


def test_sensor_dict_is_the_latest_line_the_board_printed(board: Board) -> None:
    with ArduinoSensor("arduino", str(board.link), 1000000, 50.0) as sensor:
        line = b'{"Day": "monday", "Time": 12}\r\n'
        assert arrives(sensor, board, line, {"Day": "monday", "Time": 12})
        board.send(b'{"Day": "monday", ')  # a line arrives in pieces
        board.send(b'"Time": 32}\r\n{"Day": "tuesday", "Time": 52}\r\n')
        assert eventually(lambda: sensor.sensor_dict["Time"] == 52)
        assert sensor.sensor_dict["Day"] == "tuesday"
        assert sensor.read("sensor_dict") == {"Day": "tuesday", "Time": 52}
        health = sensor.health()
        assert health.connected and health.errors == 0 and health.kind == "ArduinoSensor"


def test_no_line_yet_is_no_value_yet(board: Board) -> None:
    with ArduinoSensor("arduino", str(board.link)) as sensor:
        with pytest.raises(SensorError, match=r"^ArduinoSensor 'arduino' gave no value in 0.5 s$"):
            sensor.wait_first(0.5)  # an open port with nothing printed yet is not an empty dict
        assert sensor.health().connected and sensor.health().age_s is None
        assert arrives(sensor, board, b'{"Time": 7}\n', {"Time": 7})


def test_broken_lines_are_said_once_counted_and_skipped(
    board: Board, caplog: pytest.LogCaptureFixture
) -> None:
    with caplog.at_level(logging.WARNING), ArduinoSensor("arduino", str(board.link)) as sensor:
        assert arrives(sensor, board, b'{"Time": 1}\n', {"Time": 1})
        board.send(b'{"Time": 2, "Da\n[1, 2]\n{"Time": 3}\n')
        assert eventually(lambda: sensor.sensor_dict == {"Time": 3})
        board.send(b"\xff\xfe garbage\n")
        assert eventually(lambda: sensor.health().errors == 3)
        health = sensor.health()
        assert health.connected and "not a JSON object line" in health.last_error
        board.send(b'{"Time": 4}\n')
        assert eventually(lambda: sensor.sensor_dict == {"Time": 4})
    said = [r for r in caplog.records if "not a JSON object line" in r.getMessage()]
    assert len(said) == 1 and said[0].levelno == logging.WARNING


def test_an_unplugged_board_is_lost_once_then_resumes(
    board: Board, caplog: pytest.LogCaptureFixture
) -> None:
    with caplog.at_level(logging.WARNING), ArduinoSensor("arduino", str(board.link)) as sensor:
        assert arrives(sensor, board, b'{"Time": 1}\n', {"Time": 1})
        board.unplug()
        board.link.unlink()
        assert eventually(lambda: not sensor.health().connected)
        lost = sensor.health()
        assert lost.losses == 1 and lost.down_s >= 0 and str(board.link) in lost.last_error
        assert sensor.sensor_dict == {"Time": 1}  # the last value stays readable
        board.plug()
        assert arrives(sensor, board, b'{"Time": 2}\n', {"Time": 2})
        assert sensor.health().connected
        assert sensor.health().losses == 1
    messages = [r.getMessage() for r in caplog.records if r.levelno == logging.WARNING]
    assert len([m for m in messages if "ArduinoSensor arduino lost" in m]) == 1
    assert len([m for m in messages if "ArduinoSensor arduino is back" in m]) == 1


def test_a_pypot_config_entry_is_robot_dot_name(board: Board) -> None:
    data = load_profile("ergo-jr").to_pypot_dict()
    data["sensors"] = {
        "arduino": {"type": "ArduinoSensor", "port": str(board.link), "baud": 1000000}
    }
    with from_config(RobotConfig.from_dict(data), sim=True) as robot:
        assert arrives(robot.arduino, board, b'{"light": 512}\n', {"light": 512})
        with rest(robot) as client:
            value = client.get("/sensors/arduino/registers/sensor_dict/value.json").json()
            assert value == {"sensor_dict": {"light": 512}}
        assert robot.sensor_health()["arduino"].connected
    assert robot.arduino.closed
