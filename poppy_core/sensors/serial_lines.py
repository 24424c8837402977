"""``SerialLines``: a device printing text lines on a serial port, as sensors read one.

Opened on first read, the bytes waiting split into complete lines (a line arriving in pieces is
joined; one longer than ``MAX_LINE_BYTES`` dropped and said), dropped when the port goes away
(``SensorLost``), reopened by the sensor's backoff. The Arduino and the Razor IMU read this way.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable
from typing import Any

from poppy_core.errors import SensorError
from poppy_core.sensors.base import SensorLost

MAX_LINE_BYTES = 64 * 1024
"""A line longer than this (no newline from a board printing garbage) is dropped."""

PortOpener = Callable[[str, int], Any]
"""Opens a serial port: (port, baud) -> a pyserial ``Serial``-like object."""


def open_serial(port: str, baud: int) -> Any:
    """The port through pyserial (a device path or a pyserial URL such as ``loop://``)."""
    import serial

    return serial.serial_for_url(port, baudrate=baud, timeout=0.05)


class SerialLines:
    """The lines a device prints on ``port``.

    Args:
        port: the serial device (or a pyserial URL).
        baud: its baud rate.
        bad_input: told about a line too long to keep (the sensor's ``bad_input``).
        opener: opens the port (tests, other transports).
    """

    def __init__(
        self,
        port: str,
        baud: int,
        bad_input: Callable[[str], None],
        opener: PortOpener = open_serial,
    ) -> None:
        self.port = port
        self.baud = baud
        self._bad_input = bad_input
        self._opener = opener
        self._serial: Any = None
        self._pending = b""

    def read(self) -> list[bytes]:
        """The complete lines received since the last read (stripped, empty ones left out).

        Raises:
            SensorLost: the port cannot be opened, or went away (it is dropped).
        """
        if self._serial is None:
            self.open()
        try:
            data = self._serial.read(self._serial.in_waiting or 1)
        except (OSError, ValueError) as exc:  # SerialException is an OSError
            self.close()
            raise SensorLost(f"{self.port}: {exc}") from None
        *lines, self._pending = (self._pending + data).split(b"\n")
        if len(self._pending) > MAX_LINE_BYTES:
            self._pending = b""
            self._bad_input(f"{self.port}: a line longer than {MAX_LINE_BYTES} bytes, dropped")
        return [line for line in (raw.strip() for raw in lines) if line]

    def open(self) -> None:
        """Open the port; what was half-received before is not a line.

        Raises:
            SensorLost: it cannot be opened.
        """
        try:
            self._serial = self._opener(self.port, self.baud)
        except (OSError, ValueError) as exc:
            raise SensorLost(f"cannot open {self.port}: {exc}") from None
        self._pending = b""

    def reopen(self, sensor: str) -> None:
        """Open the port again for the sensor's backoff (``Sensor.reconnect``).

        Raises:
            SensorError: it cannot be opened yet.
        """
        try:
            self.open()
        except SensorLost as exc:
            raise SensorError(str(exc), sensor=sensor) from None

    def close(self) -> None:
        """Close the port (it is opened again on the next read)."""
        serial, self._serial = self._serial, None
        if serial is not None:
            with contextlib.suppress(OSError, ValueError):
                serial.close()
