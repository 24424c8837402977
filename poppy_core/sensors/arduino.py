"""``ArduinoSensor``: a board printing one JSON object a line on a serial port (pypot's).

pypot's config entry: ``{"type": "ArduinoSensor", "port": "/dev/ttyACM0", "baud": 1000000,
"sync_freq": 50.0}``; ``sensor_dict`` is the latest object the board printed (``{"Time":
1234}``). A line that is not a JSON object is counted in health (the first one logged at
WARNING) and skipped; a port that goes away (unplugged) is lost and reopened with backoff.
"""

from __future__ import annotations

import contextlib
import json
from collections.abc import Callable
from typing import Any, ClassVar

from poppy_core.errors import SensorError
from poppy_core.sensors.base import Sensor, SensorLost

DEFAULT_BAUD = 115200
DEFAULT_SYNC_HZ = 50.0
MAX_LINE_BYTES = 64 * 1024
"""A line longer than this (no newline from a board printing garbage) is dropped."""

PortOpener = Callable[[str, int], Any]
"""Opens a serial port: (port, baud) -> a pyserial ``Serial``-like object."""


def open_serial(port: str, baud: int) -> Any:
    """The port through pyserial (a device path or a pyserial URL such as ``loop://``)."""
    import serial

    return serial.serial_for_url(port, baudrate=baud, timeout=0.05)


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
        self._opener = opener
        self._serial: Any = None
        self._pending = b""
        self._latest: dict[str, Any] = {}

    @property
    def sensor_dict(self) -> dict[str, Any]:
        """The latest object the board printed (a copy; waits for the first one)."""
        self.wait_first()
        return dict(self._latest)

    def update(self) -> bool | None:
        if self._serial is None:
            self._open()
        try:
            waiting = self._serial.in_waiting
            data = self._serial.read(waiting or 1)
        except (OSError, ValueError) as exc:  # SerialException is an OSError
            self._drop()
            raise SensorLost(f"{self.port}: {exc}") from None
        # only a new object is a value: health's age and rate are the board's lines
        return self._take(data)

    def _take(self, data: bytes) -> bool:
        """Parse the complete lines in ``data``; True when one gave a new object."""
        *lines, self._pending = (self._pending + data).split(b"\n")
        if len(self._pending) > MAX_LINE_BYTES:
            self._pending = b""
            self.bad_input(f"{self.port}: a line longer than {MAX_LINE_BYTES} bytes, dropped")
        fresh = False
        for raw in lines:
            line = raw.strip()
            if not line:
                continue
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

    def _open(self) -> None:
        try:
            self._serial = self._opener(self.port, self.baud)
        except (OSError, ValueError) as exc:
            raise SensorLost(f"cannot open {self.port}: {exc}") from None
        # what was half-received before the port (re)opened is not a line
        self._pending = b""

    def reconnect(self) -> None:
        try:
            self._open()
        except SensorLost as exc:
            raise SensorError(str(exc), sensor=self.name) from None

    def _drop(self) -> None:
        serial, self._serial = self._serial, None
        if serial is not None:
            with contextlib.suppress(OSError, ValueError):
                serial.close()

    def release(self) -> None:
        self._drop()
