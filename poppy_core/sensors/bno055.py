"""``BNO055``: Bosch's 9-axis IMU with its own sensor fusion, on I2C through smbus2.

Config entry: ``{"type": "BNO055", "i2c_pin": 1, "address": 40, "sync_freq": 50.0}`` (40 is
0x28, the chip's address with COM3 low; 0x29 with it high).

Registers (Bosch Sensortec, "BNO055 Intelligent 9-axis absolute orientation sensor" data
sheet, BST-BNO055-DS000, section 4.3 "Register description", page 0): CHIP_ID 0x00 reads
0xA0; OPR_MODE 0x3D, where 0x00 is CONFIG and 0x0C NDOF (fusion of the three sensors, absolute
orientation); switching from CONFIG takes 7 ms, to CONFIG 19 ms. Data, little-endian int16
triples, in the default units (UNIT_SEL 0x3B at reset: m/s², degrees per second, degrees):
ACC_DATA at 0x08 (100 LSB per m/s², gravity included), GYR_DATA at 0x14 (16 LSB per dps),
EUL_DATA at 0x1A (heading, roll, pitch; 16 LSB per degree; heading 0-360 clockwise).
The chip's axes (placement P1, the reset default) are x, y, z right-handed with z up when it
lies flat: the frame of ``poppy_core.sensors.imu`` up to the heading, which turns clockwise
(yaw = -heading, from -180 to 180).
"""

from __future__ import annotations

import contextlib
import struct
import threading
from typing import Any

from poppy_core.errors import SensorError
from poppy_core.sensors.base import SensorLost
from poppy_core.sensors.i2c import BusOpener, open_smbus
from poppy_core.sensors.imu import Imu

DEFAULT_BNO055_ADDRESS = 0x28
DEFAULT_BNO055_HZ = 50.0
CHIP_ID_REGISTER = 0x00
CHIP_ID = 0xA0
OPR_MODE_REGISTER = 0x3D
CONFIG_MODE = 0x00
NDOF_MODE = 0x0C
TO_NDOF_S = 0.007
TO_CONFIG_S = 0.019
ACC_DATA = 0x08
GYR_DATA = 0x14
EUL_DATA = 0x1A
ACC_LSB = 100.0
GYR_LSB = 16.0
EUL_LSB = 16.0


def _triple(data: list[int], scale: float) -> tuple[float, float, float]:
    x, y, z = struct.unpack("<hhh", bytes(data))
    return x / scale, y / scale, z / scale


class BNO055(Imu):
    """A BNO055 in NDOF mode: orientation, angular velocity and acceleration.

    Args:
        name: the sensor's name (``robot.<name>``).
        i2c_pin: the I2C bus number (1 is /dev/i2c-1; pypot's key name for it).
        address: the chip's 7-bit address (0x28 or 0x29).
        rate_hz: reads per second.
        opener: opens the bus (tests: a fake bus).
    """

    def __init__(
        self,
        name: str,
        i2c_pin: int,
        address: int = DEFAULT_BNO055_ADDRESS,
        rate_hz: float = DEFAULT_BNO055_HZ,
        *,
        opener: BusOpener = open_smbus,
    ) -> None:
        super().__init__(name, rate_hz)
        self.i2c_pin = i2c_pin
        self.address = address
        self._opener = opener
        self._bus: Any = None
        self._pause = threading.Event()

    def update(self) -> bool | None:
        if self._bus is None:
            self._open()
        try:
            accel = _triple(self._bus.read_i2c_block_data(self.address, ACC_DATA, 6), ACC_LSB)
            rates = _triple(self._bus.read_i2c_block_data(self.address, GYR_DATA, 6), GYR_LSB)
            euler = _triple(self._bus.read_i2c_block_data(self.address, EUL_DATA, 6), EUL_LSB)
        except OSError as exc:
            self._drop()
            raise SensorLost(f"{self._where()}: {exc}") from None
        heading, roll, pitch = euler
        yaw = -heading if heading <= 180.0 else 360.0 - heading
        self._set((yaw, pitch, roll), rates, accel)
        return None

    def _where(self) -> str:
        return f"I2C bus {self.i2c_pin} address {self.address:#04x}"

    def _open(self) -> None:
        """Open the bus, check the chip's ID and start its fusion (NDOF)."""
        try:
            bus = self._opener(self.i2c_pin)
        except OSError as exc:
            raise SensorLost(f"cannot open I2C bus {self.i2c_pin}: {exc}") from None
        try:
            chip = bus.read_byte_data(self.address, CHIP_ID_REGISTER)
            if chip != CHIP_ID:
                raise SensorLost(
                    f"{self._where()} is not a BNO055 (chip ID {chip:#04x}, not {CHIP_ID:#04x})"
                )
            bus.write_byte_data(self.address, OPR_MODE_REGISTER, CONFIG_MODE)
            self._pause.wait(TO_CONFIG_S)
            bus.write_byte_data(self.address, OPR_MODE_REGISTER, NDOF_MODE)
            self._pause.wait(TO_NDOF_S)
        except OSError as exc:
            with contextlib.suppress(OSError):
                bus.close()
            raise SensorLost(f"{self._where()}: {exc}") from None
        except SensorLost:
            with contextlib.suppress(OSError):
                bus.close()
            raise
        self._bus = bus

    def reconnect(self) -> None:
        try:
            self._open()
        except SensorLost as exc:
            raise SensorError(str(exc), sensor=self.name) from None

    def _drop(self) -> None:
        bus, self._bus = self._bus, None
        if bus is not None:
            with contextlib.suppress(OSError):
                bus.close()

    def release(self) -> None:
        self._drop()
