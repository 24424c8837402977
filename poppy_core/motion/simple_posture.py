"""``SimplePosture``: go to a posture in a given time, then end (pypot's subclass idioms too)."""

from __future__ import annotations

import inspect
import time
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any, ClassVar

from poppy_core import checks
from poppy_core.errors import ArgumentError
from poppy_core.motion.primitive import Primitive

if TYPE_CHECKING:
    from poppy_core.robot import Robot


def _own_target(cls: type) -> bool:
    """True when ``cls`` defines ``target_position`` itself and it cannot be set: pypot's
    idiom, a read-only property (or a class attribute) computing the posture."""
    found = inspect.getattr_static(cls, "target_position", None)
    if found is SimplePosture.__dict__["target_position"]:
        return False
    return not isinstance(found, property) or found.fset is None


def _motor_name(motor: Any) -> str:
    return motor if isinstance(motor, str) else str(motor.name)


class SimplePosture(Primitive):
    """Goes to a posture (motor name -> degrees) in ``duration`` seconds, then ends.

    ``start()`` then ``wait_to_stop()`` (or ``go(wait=True)``) blocks until it is reached. The
    moving speeds of the posture's motors are given back when it ends (a ``dummy`` goto sets
    them), as pypot's posture does.

    A subclass may define, as pypot's postures do, ``target_position`` as a read-only property
    (computed in the primitive's thread, at each start) and ``leds``, a mapping motor (or motor
    name) -> colour lit while it moves and turned off at its end.

    Args:
        robot: the robot.
        duration: seconds to reach the posture.
        target_position: the posture; every motor at 0° when None. A subclass that defines its
            own read-only ``target_position`` takes none.

    Raises:
        ArgumentError: a ``target_position`` given to a subclass that defines its own.
    """

    properties: ClassVar[Sequence[str]] = ("duration", "target_position")
    methods: ClassVar[Sequence[str]] = (*Primitive.methods, "go")

    def __init__(
        self,
        robot: Robot,
        duration: float = 2.0,
        target_position: Mapping[str, float] | None = None,
    ) -> None:
        super().__init__(robot)
        self.duration = duration
        self._speeds: dict[str, float] = {}
        self._lit: list[str] = []
        if _own_target(type(self)):
            if target_position is not None:
                raise ArgumentError(
                    f"{type(self).__name__} defines its target_position itself: build it "
                    "without one",
                    field="target_position",
                )
            return
        if target_position is None:
            target_position = {m.name: 0.0 for m in robot.motors}
        self.target_position = dict(target_position)

    @property
    def target_position(self) -> dict[str, float]:
        """The posture: motor name -> degrees (unknown motors are refused when set)."""
        return self._target

    @target_position.setter
    def target_position(self, value: Mapping[str, float]) -> None:
        for name in value:
            self.real_robot.motor(name)  # raises UnknownMotorError naming the known motors
        self._target = dict(value)

    @property
    def duration(self) -> float:
        """Seconds to reach the posture (>= 0)."""
        return self._duration

    @duration.setter
    def duration(self, value: float) -> None:
        self._duration = checks.duration(value)

    def _posture(self) -> dict[str, float]:
        """The posture now: checked (a subclass's property is read in the primitive's thread)."""
        posture = {str(name): float(value) for name, value in self.target_position.items()}
        for name in posture:
            self.real_robot.motor(name)
        return posture

    def setup(self) -> None:
        """Check the posture, note its motors' speeds, stiffen them and light the ``leds``."""
        posture = self._posture()
        self._speeds = {name: self.real_robot.motor(name).moving_speed for name in posture}
        for name in posture:
            self.robot.motor(name).compliant = False
        leds = getattr(self, "leds", None) or {}
        self._lit = []
        for motor, colour in dict(leds).items():
            name = _motor_name(motor)
            self.robot.motor(name).led = colour
            self._lit.append(name)

    def run(self) -> None:
        """Move, and return once the posture is reached (or when stopped)."""
        start = time.monotonic()
        self.robot.goto_position(self._posture(), self.duration)
        self.sleep(self.duration - (time.monotonic() - start))

    def teardown(self) -> None:
        """Give the motors back their moving speeds and turn the ``leds`` off."""
        for name, speed in self._speeds.items():
            self.robot.motor(name).moving_speed = speed
        for name in self._lit:
            self.robot.motor(name).led = "off"

    def go(self, wait: bool = True) -> None:
        """Start (or restart) and, with ``wait``, block until the posture is reached."""
        self.start()
        if wait:
            self.wait_to_stop()
