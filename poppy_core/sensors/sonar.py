"""``SonarSensor``: a Devantech SRF-02 ultrasonic range finder on I2C, through smbus2.

pypot's config entry: ``{"type": "SonarSensor", "i2c_pin": 1, "address": 112, "sync_freq":
50.0}`` (``i2c_pin`` is the bus number, /dev/i2c-1; 112 = 0x70, the module's default);
``distance`` is in metres, the median of the last five ranges as pypot's.

The SRF-02's registers (Devantech's "SRF02 Ultrasonic range finder, I2C mode" technical
specification, robot-electronics.co.uk/htm/srf02techI2C.htm): writing 0x51 to register 0
starts a ranging with the result in centimetres; it takes up to 65 ms, during which the module
does not answer on the bus; the result is then in registers 2 (high byte) and 3 (low byte).
"""

from __future__ import annotations

import contextlib
import statistics
import threading
from collections import deque
from typing import Any, ClassVar

from poppy_core.errors import SensorError
from poppy_core.sensors.base import Sensor, SensorLost
from poppy_core.sensors.i2c import BusOpener, open_smbus

DEFAULT_ADDRESS = 0x70
DEFAULT_SONAR_HZ = 50.0
COMMAND_REGISTER = 0
RANGE_CM = 0x51
RANGE_HIGH_REGISTER = 2
RANGE_LOW_REGISTER = 3
RANGING_S = 0.07
"""The SRF-02 ranges for up to 65 ms; the result is read after this."""
MEDIAN_OF = 5


class SonarSensor(Sensor):
    """The distance an SRF-02 measures, in metres (pypot's ``SonarSensor``).

    Args:
        name: the sensor's name (``robot.<name>``).
        i2c_pin: the I2C bus number (pypot's name for it).
        address: the module's 7-bit address (0x70 by default; 0x70-0x7F).
        rate_hz: rangings per second asked for (one takes 70 ms: about 14 at most).
        opener: opens the bus (tests: a fake bus).
    """

    registers: ClassVar[tuple[str, ...]] = ("distance",)

    def __init__(
        self,
        name: str,
        i2c_pin: int,
        address: int = DEFAULT_ADDRESS,
        rate_hz: float = DEFAULT_SONAR_HZ,
        *,
        opener: BusOpener = open_smbus,
    ) -> None:
        super().__init__(name, rate_hz)
        self.i2c_pin = i2c_pin
        self.address = address
        self._opener = opener
        self._bus: Any = None
        self._ranges: deque[int] = deque(maxlen=MEDIAN_OF)
        self._pause = threading.Event()

    @property
    def distance(self) -> float:
        """Metres to the nearest echo (median of the last five rangings)."""
        self.wait_first()
        return statistics.median(self._ranges) / 100.0

    def update(self) -> bool | None:
        if self._bus is None:
            self._open()
        try:
            self._bus.write_byte_data(self.address, COMMAND_REGISTER, RANGE_CM)
            self._pause.wait(RANGING_S)
            high = self._bus.read_byte_data(self.address, RANGE_HIGH_REGISTER)
            low = self._bus.read_byte_data(self.address, RANGE_LOW_REGISTER)
        except OSError as exc:
            self._drop()
            raise SensorLost(f"I2C bus {self.i2c_pin} address {self.address:#04x}: {exc}") from None
        self._ranges.append((high << 8) | low)
        return None

    def _open(self) -> None:
        try:
            self._bus = self._opener(self.i2c_pin)
        except OSError as exc:
            raise SensorLost(f"cannot open I2C bus {self.i2c_pin}: {exc}") from None

    def reconnect(self) -> None:
        """Reopen the bus and ask the module its software revision (register 0)."""
        try:
            self._open()
            self._bus.read_byte_data(self.address, COMMAND_REGISTER)
        except (SensorLost, OSError) as exc:
            self._drop()
            raise SensorError(str(exc), sensor=self.name) from None

    def _drop(self) -> None:
        bus, self._bus = self._bus, None
        if bus is not None:
            with contextlib.suppress(OSError):
                bus.close()

    def release(self) -> None:
        self._drop()
