"""Safety primitives of Torso and Humanoid: torque limited to the need, temperature watch."""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, ClassVar

from poppy_core import checks
from poppy_core.creatures.alarm import AlarmSound
from poppy_core.motion import LoopPrimitive

if TYPE_CHECKING:
    from poppy_core.robot import Robot

logger = logging.getLogger(__name__)

# Poppy documentation (limit_torque): "Each motor automatically sets the minimal torque needed to
# reach its goal position". poppy-humanoid's numbers are not installed here; chosen values: the
# torque grows linearly with the distance to the goal, from MIN at 0° to MAX at 30° and beyond,
# updated at 20 Hz.
LIMIT_TORQUE_HZ = 20.0
LIMIT_TORQUE_MIN_PCT = 20.0
LIMIT_TORQUE_MAX_PCT = 80.0
LIMIT_TORQUE_FULL_AT_DEG = 30.0

# Poppy documentation (temperature_monitoring): "check the temperature of all motors ... if one
# is too hot". Chosen: 55 °C, well below the factory Temperature Limit of the Poppy servos
# (e-manual: MX-28 80 °C, AX-12A 70 °C); checked every second, the rate the sync loop reads
# temperatures at (poppy_core.robot.sync).
TEMPERATURE_LIMIT_C = 55.0
TEMPERATURE_CHECK_HZ = 1.0
# A hot motor is reported again only after cooling this far below the limit.
TEMPERATURE_HYSTERESIS_C = 2.0
# The alarm sounds when a motor gets too hot, then this often while one stays too hot.
ALARM_REPEAT_S = 10.0


def _torque_motors(robot: Robot) -> list[str]:
    return [m.name for m in robot.motors if m.model.has_torque_limit]


class LimitTorque(LoopPrimitive):
    """Each motor gets the torque it needs: more the farther it is from its goal (looping).

    The previous torque limits are given back when it stops.

    Args:
        robot: the robot (motors without a torque limit register are left alone).
        freq: updates per second.
        min_torque: torque limit (%) of a motor at its goal.
        max_torque: torque limit (%) of a motor ``full_torque_at_deg`` or more from its goal.
        full_torque_at_deg: distance (degrees) where ``max_torque`` is reached.
    """

    properties: ClassVar[Sequence[str]] = (
        "min_torque",
        "max_torque",
        "full_torque_at_deg",
        "update_freq",
    )

    def __init__(
        self,
        robot: Robot,
        freq: float = LIMIT_TORQUE_HZ,
        min_torque: float = LIMIT_TORQUE_MIN_PCT,
        max_torque: float = LIMIT_TORQUE_MAX_PCT,
        full_torque_at_deg: float = LIMIT_TORQUE_FULL_AT_DEG,
    ) -> None:
        super().__init__(robot, freq)
        self.min_torque = min_torque
        self.max_torque = max_torque
        self.full_torque_at_deg = full_torque_at_deg
        self._previous: dict[str, float] = {}

    @property
    def min_torque(self) -> float:
        """Torque limit (%) at the goal, 0..100."""
        return self._min

    @min_torque.setter
    def min_torque(self, value: float) -> None:
        self._min = _percent("min_torque", value)

    @property
    def max_torque(self) -> float:
        """Torque limit (%) far from the goal, 0..100."""
        return self._max

    @max_torque.setter
    def max_torque(self, value: float) -> None:
        self._max = _percent("max_torque", value)

    @property
    def full_torque_at_deg(self) -> float:
        """Distance to the goal (degrees, > 0) from which ``max_torque`` applies."""
        return self._full_at

    @full_torque_at_deg.setter
    def full_torque_at_deg(self, value: float) -> None:
        checks.positive(value, "full_torque_at_deg")
        self._full_at = float(value)

    def torque_for(self, distance_deg: float) -> float:
        """The torque limit (%) for a motor ``distance_deg`` away from its goal."""
        share = min(abs(distance_deg) / self.full_torque_at_deg, 1.0)
        return self.min_torque + share * (self.max_torque - self.min_torque)

    def setup(self) -> None:
        """Note the torque limits to give back."""
        robot = self.real_robot
        self._previous = {n: robot.motor(n).torque_limit for n in _torque_motors(robot)}

    def update(self) -> None:
        """Request each motor's torque from its distance to its goal."""
        for name in self._previous:
            real = self.real_robot.motor(name)
            distance = real.goal_position - real.present_position
            self.robot.motor(name).torque_limit = self.torque_for(distance)

    def teardown(self) -> None:
        """Give the torque limits back."""
        for name, value in self._previous.items():
            self.robot.motor(name).torque_limit = value


def _percent(name: str, value: float) -> float:
    return checks.in_range(value, 0.0, 100.0, name, "%")


class TemperatureMonitor(LoopPrimitive):
    """Warns when a motor gets too hot, with a sound as pypot did; started by default (looping).

    The warning goes to the ``poppy_core.creatures.safety`` logger (the robot's page shows it in
    its log), ``hot_motors`` lists the motors above the limit, and the alarm sound plays when a
    motor gets too hot, then every ``ALARM_REPEAT_S`` while one stays too hot (pypot played it at
    every check, every 2 s). A machine without audio says so once in the log.

    Args:
        robot: the robot.
        freq: checks per second.
        temperature_limit: °C above which a motor is too hot (``temp_limit``: pypot's name).
        player: the program that plays the sound (pypot: ``'aplay'``; None: the first of
            aplay, paplay, pw-play and afplay found).
        sound: the WAV file played (None: poppy's own tone).
    """

    properties: ClassVar[Sequence[str]] = ("temperature_limit", "update_freq", "hot_motors")

    def __init__(
        self,
        robot: Robot,
        freq: float = TEMPERATURE_CHECK_HZ,
        temperature_limit: float = TEMPERATURE_LIMIT_C,
        player: str | None = None,
        sound: str | Path | None = None,
        *,
        temp_limit: float | None = None,
    ) -> None:
        super().__init__(robot, freq)
        self.temperature_limit = temperature_limit if temp_limit is None else temp_limit
        self.hot_motors: list[str] = []
        self.alarm = AlarmSound(player, sound)
        self._last_alarm = -math.inf

    @property
    def temperature_limit(self) -> float:
        """°C above which a motor is reported."""
        return self._limit

    @temperature_limit.setter
    def temperature_limit(self, value: float) -> None:
        checks.positive(value, "temperature_limit")
        self._limit = float(value)

    @property
    def temp_limit(self) -> float:
        """pypot's name for ``temperature_limit``."""
        return self.temperature_limit

    @temp_limit.setter
    def temp_limit(self, value: float) -> None:
        self.temperature_limit = value

    @property
    def player(self) -> str | None:
        """The program that plays the alarm (None: found on the PATH)."""
        return self.alarm.player

    @player.setter
    def player(self, value: str | None) -> None:
        self.alarm.player = value

    @property
    def sound(self) -> str | Path | None:
        """The alarm's WAV file (None: poppy's own tone)."""
        return self.alarm.sound

    @sound.setter
    def sound(self, value: str | Path | None) -> None:
        self.alarm.sound = value

    def setup(self) -> None:
        """Forget earlier reports."""
        self.hot_motors = []
        self._last_alarm = -math.inf

    def update(self) -> None:
        """Check every motor; warn once per motor each time it goes above the limit, and sound
        the alarm while one is too hot."""
        hot = list(self.hot_motors)
        new = False
        for motor in self.real_robot.motors:
            if not motor.online:
                continue
            temperature = motor.present_temperature
            if temperature > self.temperature_limit and motor.name not in hot:
                hot.append(motor.name)
                new = True
                logger.warning(
                    "%s is too hot: %.0f °C (limit %.0f °C): let it cool down (turn it compliant)",
                    motor.name,
                    temperature,
                    self.temperature_limit,
                )
            elif motor.name in hot and temperature < self.temperature_limit - (
                TEMPERATURE_HYSTERESIS_C
            ):
                hot.remove(motor.name)
                logger.info("%s cooled down: %.0f °C", motor.name, temperature)
        self.hot_motors = hot
        now = time.monotonic()
        if hot and (new or now - self._last_alarm >= ALARM_REPEAT_S):
            self._last_alarm = now
            self.alarm.play()

    def teardown(self) -> None:
        """Let a sound still playing end."""
        self.alarm.close()
