"""An I2C bus opened through smbus2 for the sensors on one (the sonar, the BNO055 IMU)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from poppy_core.errors import SensorError

BusOpener = Callable[[int], Any]
"""Opens I2C bus number N: an ``smbus2.SMBus``-like object."""


def open_smbus(bus: int) -> Any:
    """/dev/i2c-<bus> through smbus2.

    Raises:
        SensorError: smbus2 is not installed (the ``i2c`` extra), in one line.
    """
    try:
        import smbus2
    except ImportError:
        raise SensorError("I2C sensors need smbus2: pip install 'poppy[i2c]'") from None
    return smbus2.SMBus(bus)
