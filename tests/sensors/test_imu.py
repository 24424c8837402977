"""IMUs: a Razor AHRS printing on a real pseudo-terminal, a BNO055 behind a fake I2C bus that
answers as the chip's registers do, the still IMU of the ideal simulation and the MuJoCo one."""

from __future__ import annotations

import logging
import math
import struct
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from poppy_core import from_config
from poppy_core.errors import ConfigError
from poppy_core.robot import RobotConfig, load_profile
from poppy_core.sensors.bno055 import BNO055
from poppy_core.sensors.imu import GRAVITY, RazorIMU, angles_of, quaternion_of
from tests.helpers.sensor_rest import rest
from tests.helpers.waiting import eventually
from tests.sensors.test_arduino import Board

NOT_ANSWERING = 121  # EREMOTEIO: the I2C adapter saw no acknowledge


@pytest.fixture
def razor(tmp_path: Path) -> Iterator[Board]:
    made = Board(tmp_path / "ttyUSB0")
    yield made
    made.close()


def shows(imu: RazorIMU, board: Board, line: bytes, register: str, expected: object) -> bool:
    """The board prints ``line`` 50 times a second, as the firmware does, until it shows."""
    imu.start()

    def shown() -> bool:
        board.send(line)
        return imu.health().age_s is not None and getattr(imu, register) == expected

    return eventually(shown, timeout_s=10, interval_s=0.02)


@given(
    st.floats(-179, 179),
    st.floats(-89, 89),
    st.floats(-179, 179),
)
def test_angles_survive_the_quaternion(yaw: float, pitch: float, roll: float) -> None:
    quaternion = quaternion_of(yaw, pitch, roll)
    assert math.isclose(sum(v * v for v in quaternion), 1.0, rel_tol=1e-9)
    back = angles_of(*quaternion)
    for got, want in zip(back, (yaw, pitch, roll), strict=True):
        assert math.isclose(got, want, abs_tol=1e-6)


def test_the_razors_angles_in_the_ros_frame(razor: Board) -> None:
    with RazorIMU("imu", str(razor.link)) as imu:
        line = b"#YPR=10.50,-3.25,1.00\r\n"  # the firmware's default output: yaw, pitch, roll
        expected = {"yaw": -10.5, "pitch": 3.25, "roll": 1.0}
        assert shows(imu, razor, line, "orientation", expected)
        assert imu.angular_velocity is None and imu.acceleration is None
        assert imu.read("quaternion") == [round(v, 6) for v in quaternion_of(-10.5, 3.25, 1.0)]
        assert imu.health().kind == "RazorIMU" and imu.health().errors == 0


def test_the_razors_extended_lines_give_rates_and_accelerations(razor: Board) -> None:
    with RazorIMU("imu", str(razor.link)) as imu:
        # razor_imu_9dof's firmware: angles, accelerations (256 = 1 g), rates (rad/s), z down
        line = b"#YPRAG=0.00,0.00,0.00,0.00,0.00,-256.00,0.10,0.00,-0.50\r\n"
        assert shows(imu, razor, line, "orientation", {"yaw": 0.0, "pitch": 0.0, "roll": 0.0})
        assert imu.acceleration == {"x": 0.0, "y": 0.0, "z": round(-GRAVITY, 4)}
        rates = imu.angular_velocity
        assert rates is not None
        assert rates["x"] == round(math.degrees(0.1), 4) and rates["z"] == round(
            math.degrees(0.5), 4
        )
        razor.send(b"#YPRAG=1,2,3,4,5,6,0,0,0\n#YPR=")  # the next line arrives in pieces
        razor.send(b"5,6,7\n")
        assert eventually(lambda: imu.orientation == {"yaw": -5.0, "pitch": -6.0, "roll": 7.0})


def test_a_broken_razor_line_is_said_once_and_skipped(
    razor: Board, caplog: pytest.LogCaptureFixture
) -> None:
    with caplog.at_level(logging.WARNING), RazorIMU("imu", str(razor.link)) as imu:
        assert shows(
            imu, razor, b"#YPR=1,2,3\n", "orientation", {"yaw": -1, "pitch": -2, "roll": 3}
        )
        razor.send(b"#YPR=1,2\n#YPR=nan,0,0\nRazor AHRS v1.4.2\n#YPR=4,5,6\n")
        assert eventually(lambda: imu.orientation["roll"] == 6)
        assert eventually(lambda: imu.health().errors == 3)
        assert "not a #YPR= or #YPRAG= line" in imu.health().last_error
    said = [r for r in caplog.records if "not a #YPR= or #YPRAG= line" in r.getMessage()]
    assert len(said) == 1


def test_an_unplugged_razor_is_lost_once_then_resumes(
    razor: Board, caplog: pytest.LogCaptureFixture
) -> None:
    with caplog.at_level(logging.WARNING), RazorIMU("imu", str(razor.link)) as imu:
        assert shows(imu, razor, b"#YPR=1,0,0\n", "orientation", {"yaw": -1, "pitch": 0, "roll": 0})
        razor.unplug()
        razor.link.unlink()
        assert eventually(lambda: not imu.health().connected)
        assert imu.orientation["yaw"] == -1  # the last value stays readable
        razor.plug()
        assert shows(imu, razor, b"#YPR=2,0,0\n", "orientation", {"yaw": -2, "pitch": 0, "roll": 0})
    messages = [r.getMessage() for r in caplog.records]
    assert len([m for m in messages if "RazorIMU imu lost" in m]) == 1
    assert len([m for m in messages if "RazorIMU imu is back" in m]) == 1


class FakeBno055Bus:
    """An I2C bus with a BNO055 at ``address`` (page 0 registers of Bosch's data sheet)."""

    def __init__(self, address: int = 0x28, chip_id: int = 0xA0) -> None:
        self.address = address
        self.registers = bytearray(0x80)
        self.registers[0x00] = chip_id
        self.modes: list[int] = []
        self.present = True
        self._lock = threading.Lock()

    def set_triple(self, register: int, values: tuple[int, int, int]) -> None:
        with self._lock:
            self.registers[register : register + 6] = struct.pack("<hhh", *values)

    def _answer(self, address: int) -> None:
        if not self.present or address != self.address:
            raise OSError(NOT_ANSWERING, "Remote I/O error")

    def read_byte_data(self, address: int, register: int) -> int:
        with self._lock:
            self._answer(address)
            return self.registers[register]

    def write_byte_data(self, address: int, register: int, value: int) -> None:
        with self._lock:
            self._answer(address)
            self.registers[register] = value
            if register == 0x3D:
                self.modes.append(value)

    def read_i2c_block_data(self, address: int, register: int, length: int) -> list[int]:
        with self._lock:
            self._answer(address)
            if self.registers[0x3D] != 0x0C:
                return [0] * length  # in CONFIG mode the fusion outputs read zero
            return list(self.registers[register : register + length])

    def close(self) -> None:
        pass


def test_the_bno055_in_fusion_mode_reads_in_the_imu_frame() -> None:
    bus = FakeBno055Bus()
    bus.set_triple(0x08, (12, -34, 981))  # m/s² * 100
    bus.set_triple(0x14, (160, 0, -32))  # dps * 16
    bus.set_triple(0x1A, (350 * 16, 8 * 16, -4 * 16))  # heading, roll, pitch; degrees * 16
    with BNO055("imu", 1, opener=lambda n: bus) as imu:
        imu.start()
        assert eventually(lambda: imu.health().age_s is not None and imu.orientation["yaw"] != 0)
        assert bus.modes == [0x00, 0x0C]  # CONFIG, then NDOF
        assert imu.orientation == {"yaw": 10.0, "pitch": -4.0, "roll": 8.0}
        assert imu.acceleration == {"x": 0.12, "y": -0.34, "z": 9.81}
        assert imu.angular_velocity == {"x": 10.0, "y": 0.0, "z": -2.0}
        bus.set_triple(0x1A, (90 * 16, 0, 0))  # heading 90° clockwise: yaw -90
        assert eventually(lambda: imu.orientation["yaw"] == -90.0)


def test_a_chip_that_is_not_a_bno055_is_said(caplog: pytest.LogCaptureFixture) -> None:
    bus = FakeBno055Bus(chip_id=0x55)
    with caplog.at_level(logging.WARNING), BNO055("imu", 1, opener=lambda n: bus) as imu:
        imu.start()
        assert eventually(lambda: not imu.health().connected)
        assert "is not a BNO055 (chip ID 0x55, not 0xa0)" in imu.health().last_error
        bus.registers[0x00] = 0xA0  # the right chip plugged in
        assert eventually(lambda: imu.health().connected and imu.health().age_s is not None)


def _config(entry: dict[str, object], profile: str = "torso") -> RobotConfig:
    data = load_profile(profile).to_pypot_dict()
    data["sensors"] = {"imu": entry}
    return RobotConfig.from_dict(data)


@pytest.mark.parametrize(
    "entry",
    [{"type": "RazorIMU", "port": "/dev/ttyUSB9"}, {"type": "BNO055", "i2c_pin": 1}],
    ids=["razor", "bno055"],
)
def test_an_imu_entry_on_the_ideal_simulation_is_level_and_still(entry: dict[str, object]) -> None:
    with from_config(_config(entry), sim=True) as robot:
        assert robot.imu.orientation == {"yaw": 0.0, "pitch": 0.0, "roll": 0.0}
        assert robot.imu.acceleration == {"x": 0.0, "y": 0.0, "z": round(GRAVITY, 4)}
        with rest(robot) as client:
            value = client.get("/sensors/imu/registers/orientation/value.json").json()
        assert value == {"orientation": {"yaw": 0.0, "pitch": 0.0, "roll": 0.0}}


def test_missing_device_keys_and_the_old_refusal() -> None:
    with pytest.raises(ConfigError, match="RazorIMU needs its 'port' key"):
        _config({"type": "RazorIMU"})
    with pytest.raises(ConfigError, match="BNO055 needs its 'i2c_pin' key"):
        _config({"type": "BNO055"})
    with pytest.raises(ConfigError, match="unknown sensor type"):
        _config({"type": "IMU", "port": "/dev/ttyUSB0"})


def test_the_simulated_imu_rides_the_head(tmp_path: Path) -> None:
    entry = {"type": "RazorIMU", "port": str(tmp_path / "none"), "freq": 50.0}
    with from_config(_config(entry), sim="mujoco") as robot:
        robot.compliant = False
        imu = robot.imu
        assert type(imu).__name__ == "SimIMU" and imu.body == "head"

        def level() -> bool:
            accel = imu.acceleration
            return accel is not None and abs(accel["z"] - GRAVITY) < 0.3

        assert eventually(level, timeout_s=20)  # still: gravity up, in the mount's frame
        assert abs(imu.orientation["yaw"]) < 2
        robot.head_z.goto_position(45, 1.0)
        assert eventually(lambda: abs(imu.orientation["yaw"] - 45) < 3, timeout_s=30)
        assert eventually(level, timeout_s=20)
        started = time.monotonic()
        robot.head_z.goto_position(0, 1.0)
        assert eventually(lambda: (imu.angular_velocity or {"z": 0})["z"] < -5, timeout_s=30), (
            f"no turning read in {time.monotonic() - started:.1f} s"
        )


def test_a_simulated_imu_on_a_missing_body_is_one_line() -> None:
    entry = {"type": "BNO055", "i2c_pin": 1, "sim_body": "tail"}
    wrong = pytest.raises(ConfigError, match="no body 'tail': set its 'sim_body' to one of base,")
    with wrong, from_config(_config(entry), sim="mujoco"):
        pass
