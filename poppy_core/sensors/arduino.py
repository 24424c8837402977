"""``ArduinoSensor``: a board printing one JSON object a line on a serial port (pypot's).

pypot's config entry: ``{"type": "ArduinoSensor", "port": "/dev/ttyACM0", "baud": 1000000,
"sync_freq": 50.0}``; ``sensor_dict`` is the latest object the board printed (``{"Time":
1234}``). A line that is not a JSON object is counted in health (the first one logged at
WARNING) and skipped; a port that goes away (unplugged) is lost and reopened with backoff.
"""

from __future__ import annotations

import json
from typing import Any, ClassVar

from poppy_core.sensors.base import Sensor
from poppy_core.sensors.serial_lines import PortOpener, SerialLines, open_serial

DEFAULT_BAUD = 115200
DEFAULT_SYNC_HZ = 50.0


class ArduinoSensor(Sensor):
    """The latest JSON object a board printed on ``port`` (pypot's ``ArduinoSensor``).

    Args:
        name: the sensor's name (``robot.<name>``).
        port: the serial device (or a pyserial URL).
        baud: its baud rate.
        rate_hz: how often waiting bytes are read (pypot's ``sync_freq``).
        opener: opens the port (tests, other transports).
    """

    registers: ClassVar[tuple[str, ...]] = ("sensor_dict",)

    def __init__(
        self,
        name: str,
        port: str,
        baud: int = DEFAULT_BAUD,
        rate_hz: float = DEFAULT_SYNC_HZ,
        *,
        opener: PortOpener = open_serial,
    ) -> None:
        super().__init__(name, rate_hz)
        self.port = port
        self.baud = baud
        self._lines = SerialLines(port, baud, self.bad_input, opener)
        self._latest: dict[str, Any] = {}

    @property
    def sensor_dict(self) -> dict[str, Any]:
        """The latest object the board printed (a copy; waits for the first one)."""
        self.wait_first()
        return dict(self._latest)

    def update(self) -> bool | None:
        # only a new object is a value: health's age and rate are the board's lines
        fresh = False
        for line in self._lines.read():
            try:
                value = json.loads(line)
            except ValueError:
                value = None
            if not isinstance(value, dict):
                shown = line[:60].decode(errors="replace")
                self.bad_input(f"{self.port}: not a JSON object line: {shown!r}")
                continue
            self._latest = value
            fresh = True
        return fresh

    def reconnect(self) -> None:
        self._lines.reopen(self.name)

    def release(self) -> None:
        self._lines.close()
