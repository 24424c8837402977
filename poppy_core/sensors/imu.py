"""IMUs: orientation, angular velocity and acceleration of a robot part (``robot.imu``).

One frame for every IMU, whatever the device (ROS's REP 103): x forward, y left, z up;
``orientation`` is yaw (about z), pitch (about y) and roll (about x) in degrees, applied in
that order (Z-Y-X), counter-clockwise positive; ``angular_velocity`` in degrees per second
about x, y, z; ``acceleration`` in m/s² along x, y, z as an accelerometer reads it (gravity
included: about +9.81 on z when still and level); ``quaternion`` (w, x, y, z) is the
orientation again. A device that does not measure one of them reads None there.

``RazorIMU``: SparkFun's 9DOF Razor with the Razor AHRS firmware, text on a serial port
(57600 baud, 50 lines a second): ``#YPR=yaw,pitch,roll`` (its default output) or the
``#YPRAG=yaw,pitch,roll,ax,ay,az,gx,gy,gz`` lines of the firmware the ROS driver
razor_imu_9dof ships. The firmware's z axis points down; the conversion to the frame above is
the ROS driver's (yaw and pitch negated; accelerations in units of 1/256 g with x negated;
rates in rad/s with y and z negated).
"""

from __future__ import annotations

import math
import threading
from typing import Any, ClassVar

from poppy_core.sensors.base import Sensor
from poppy_core.sensors.serial_lines import PortOpener, SerialLines, open_serial

GRAVITY = 9.80665
RAZOR_BAUD = 57600
RAZOR_HZ = 50.0
RAZOR_G = 256.0
"""The Razor's accelerometer: 256 counts per g (razor_imu_9dof's ``accel_factor``)."""

Vector = dict[str, float]


def vector(x: float, y: float, z: float) -> Vector:
    """``{"x": x, "y": y, "z": z}`` rounded to what an IMU resolves."""
    return {"x": round(x, 4), "y": round(y, 4), "z": round(z, 4)}


def quaternion_of(yaw_deg: float, pitch_deg: float, roll_deg: float) -> list[float]:
    """The (w, x, y, z) quaternion of Z-Y-X angles in degrees."""
    cy, sy = _half(yaw_deg)
    cp, sp = _half(pitch_deg)
    cr, sr = _half(roll_deg)
    return [
        cr * cp * cy + sr * sp * sy,
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
    ]


def angles_of(w: float, x: float, y: float, z: float) -> tuple[float, float, float]:
    """Z-Y-X angles (yaw, pitch, roll) in degrees of a (w, x, y, z) quaternion."""
    yaw = math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
    pitch = math.asin(max(-1.0, min(1.0, 2 * (w * y - z * x))))
    roll = math.atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
    return math.degrees(yaw), math.degrees(pitch), math.degrees(roll)


def _half(angle_deg: float) -> tuple[float, float]:
    half = math.radians(angle_deg) / 2
    return math.cos(half), math.sin(half)


class Imu(Sensor):
    """Base of the IMUs: subclasses' ``update`` calls ``_set`` with what they measured."""

    registers: ClassVar[tuple[str, ...]] = (
        "orientation",
        "quaternion",
        "angular_velocity",
        "acceleration",
    )

    def __init__(self, name: str, rate_hz: float, **options: Any) -> None:
        super().__init__(name, rate_hz, **options)
        self._values_lock = threading.Lock()
        self._angles: tuple[float, float, float] = (0.0, 0.0, 0.0)
        self._rates: tuple[float, float, float] | None = None
        self._accel: tuple[float, float, float] | None = None

    @property
    def orientation(self) -> dict[str, float]:
        """``{"yaw", "pitch", "roll"}`` in degrees (see the module's frame)."""
        self.wait_first()
        yaw, pitch, roll = self._angles
        return {"yaw": round(yaw, 3), "pitch": round(pitch, 3), "roll": round(roll, 3)}

    @property
    def quaternion(self) -> list[float]:
        """The orientation as ``[w, x, y, z]``."""
        self.wait_first()
        return [round(v, 6) for v in quaternion_of(*self._angles)]

    @property
    def angular_velocity(self) -> Vector | None:
        """Degrees per second about x, y, z (None: the device does not say)."""
        self.wait_first()
        rates = self._rates
        return None if rates is None else vector(*rates)

    @property
    def acceleration(self) -> Vector | None:
        """m/s² along x, y, z, gravity included (None: the device does not say)."""
        self.wait_first()
        accel = self._accel
        return None if accel is None else vector(*accel)

    def _set(
        self,
        angles: tuple[float, float, float],
        rates: tuple[float, float, float] | None = None,
        accel: tuple[float, float, float] | None = None,
    ) -> None:
        with self._values_lock:
            self._angles, self._rates, self._accel = angles, rates, accel


class StillIMU(Imu):
    """An IMU on a robot that does not move as a whole: level, still, gravity on z (the ideal
    simulation, which has no physics)."""

    def update(self) -> bool | None:
        self._set((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, GRAVITY))
        return None


class RazorIMU(Imu):
    """A 9DOF Razor IMU with the Razor AHRS firmware printing text on ``port``.

    Args:
        name: the sensor's name (``robot.<name>``).
        port: the serial device (or a pyserial URL).
        baud: its baud rate (the firmware's: 57600).
        rate_hz: how often waiting bytes are read (the firmware prints 50 lines a second).
        opener: opens the port (tests, other transports).
    """

    def __init__(
        self,
        name: str,
        port: str,
        baud: int = RAZOR_BAUD,
        rate_hz: float = RAZOR_HZ,
        *,
        opener: PortOpener = open_serial,
    ) -> None:
        super().__init__(name, rate_hz)
        self.port = port
        self.baud = baud
        self._lines = SerialLines(port, baud, self.bad_input, opener)

    def update(self) -> bool | None:
        fresh = False
        for line in self._lines.read():
            fresh = self._line(line) or fresh
        return fresh

    def _line(self, line: bytes) -> bool:
        head, _, rest = line.partition(b"=")
        try:
            values = [float(v) for v in rest.split(b",")]
        except ValueError:
            values = []
        wanted = {b"#YPR": 3, b"#YPRAG": 9}.get(head)
        if wanted is None or len(values) != wanted or not all(map(math.isfinite, values)):
            shown = line[:60].decode(errors="replace")
            self.bad_input(f"{self.port}: not a #YPR= or #YPRAG= line: {shown!r}")
            return False
        yaw, pitch, roll = values[:3]
        angles = (-yaw, -pitch, roll)
        if wanted == 3:
            self._set(angles)
            return True
        ax, ay, az, gx, gy, gz = values[3:]
        scale = GRAVITY / RAZOR_G
        accel = (-ax * scale, ay * scale, az * scale)
        rates = (math.degrees(gx), -math.degrees(gy), -math.degrees(gz))
        self._set(angles, rates, accel)
        return True

    def reconnect(self) -> None:
        self._lines.reopen(self.name)

    def release(self) -> None:
        self._lines.close()
