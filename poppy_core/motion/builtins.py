"""Built-in primitives: Sinus, Cosinus, Square, PositionWatcher and SimplePosture (its own module).

Each one can be built with the robot alone (``Sinus(robot)``): motor lists default to every motor
and the other arguments to gentle values, so ``poppy primitive run`` can start any of them.
"""

from __future__ import annotations

import io
import math
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar, TypeAlias

from poppy_core import checks
from poppy_core.errors import ArgumentError, ConfigError
from poppy_core.files import write_file
from poppy_core.motion.attached import attach_primitive
from poppy_core.motion.loop_primitive import LoopPrimitive
from poppy_core.motion.primitive import Primitive
from poppy_core.motion.sandbox import MockupMotor
from poppy_core.motion.simple_posture import SimplePosture

if TYPE_CHECKING:
    from poppy_core.robot import Motor, Robot

DEFAULT_UPDATE_HZ = 50.0
MotorList: TypeAlias = "str | Motor | MockupMotor | Sequence[str | Motor | MockupMotor] | None"


def _names(robot: Robot, motors: MotorList) -> list[str]:
    """Motor names from a motor or group name, a motor, or a list of them (every motor: None).

    Raises:
        UnknownMotorError: a name the robot does not have (the known ones are listed).
    """
    return [m.name for m in robot.motors_of(motors)]


def _check_motors(robot: Robot, names: Sequence[str]) -> None:
    for name in names:
        robot.motor(name)  # raises UnknownMotorError naming the known motors


class Sinus(LoopPrimitive):
    """A sinusoid on each listed motor: ``offset + amp * sin(2π freq t + phase)``.

    Args:
        robot: the robot.
        refresh_freq: update rate in Hz.
        motor_list: motors (names or motors); every motor when None.
        amp: amplitude in degrees.
        freq: frequency of the signal in Hz.
        offset: centre in degrees.
        phase: phase in degrees.
    """

    properties: ClassVar[Sequence[str]] = (
        "frequency",
        "amplitude",
        "offset",
        "phase",
        "motor_list",
        "update_freq",
    )

    def __init__(
        self,
        robot: Robot,
        refresh_freq: float = DEFAULT_UPDATE_HZ,
        motor_list: MotorList = None,
        amp: float = 1.0,
        freq: float = 0.5,
        offset: float = 0.0,
        phase: float = 0.0,
    ) -> None:
        super().__init__(robot, refresh_freq)
        self.motor_list = motor_list
        self.amplitude = float(amp)
        self.frequency = freq
        self.offset = float(offset)
        self.phase = float(phase)

    @property
    def motor_list(self) -> list[str]:
        """The motors driven, by name; set a name, a group, a motor or a list of them."""
        return list(self._motor_list)

    @motor_list.setter
    def motor_list(self, value: MotorList) -> None:
        self._motor_list = _names(self.real_robot, value)

    @property
    def frequency(self) -> float:
        """Frequency of the signal in Hz (>= 0)."""
        return self._signal_hz

    @frequency.setter
    def frequency(self, value: float) -> None:
        self._signal_hz = checks.non_negative(value, "frequency")

    def setup(self) -> None:
        """Check the motor names."""
        _check_motors(self.real_robot, self.motor_list)

    def signal(self, t_s: float) -> float:
        """The position (degrees) the motors get at ``t_s`` seconds."""
        angle = 2 * math.pi * self.frequency * t_s + math.radians(self.phase)
        return self.offset + self.amplitude * self.wave(angle)

    def wave(self, angle_rad: float) -> float:
        """The periodic function (period 2π, range -1..1)."""
        return math.sin(angle_rad)

    def update(self) -> None:
        """Request the signal's value at the elapsed time on every motor."""
        position = self.signal(self.elapsed_time)
        for name in self.motor_list:
            self.robot.motor(name).goal_position = position


class Cosinus(Sinus):
    """A cosinusoid on each listed motor: ``offset + amp * cos(2π freq t + phase)``."""

    def wave(self, angle_rad: float) -> float:
        """Cosine instead of sine."""
        return math.cos(angle_rad)


class Square(Sinus):
    """A square signal: ``offset + amp`` for ``duty`` of each period, then ``offset - amp``.

    Args:
        robot: the robot.
        refresh_freq: update rate in Hz.
        motor_list: motors; every motor when None.
        amp: amplitude in degrees.
        freq: frequency of the signal in Hz.
        offset: centre in degrees.
        phase: phase in degrees.
        duty: share of the period spent high (0..1).
    """

    properties: ClassVar[Sequence[str]] = (*Sinus.properties, "duty")

    def __init__(
        self,
        robot: Robot,
        refresh_freq: float = DEFAULT_UPDATE_HZ,
        motor_list: MotorList = None,
        amp: float = 1.0,
        freq: float = 1.0,
        offset: float = 0.0,
        phase: float = 0.0,
        duty: float = 0.5,
    ) -> None:
        super().__init__(robot, refresh_freq, motor_list, amp, freq, offset, phase)
        self.duty = duty

    @property
    def duty(self) -> float:
        """Share of each period spent at ``offset + amp`` (0..1)."""
        return self._duty

    @duty.setter
    def duty(self, value: float) -> None:
        if not 0.0 <= value <= 1.0:
            raise ArgumentError(
                f"duty must be between 0 and 1, got {value}", field="duty", value=value
            )
        self._duty = float(value)

    def signal(self, t_s: float) -> float:
        """High for the first ``duty`` of each period, low for the rest."""
        cycle = (self.frequency * t_s + self.phase / 360.0) % 1.0
        high = cycle < self.duty
        return self.offset + (self.amplitude if high else -self.amplitude)


class PositionWatcher(LoopPrimitive):
    """Records the present position of some motors at a rate; ``plot`` draws them.

    Args:
        robot: the robot.
        refresh_freq: samples per second.
        watched_motors: motors; every motor when None.

    Attributes:
        times: seconds since the start of each sample.
        record_positions: motor name -> its positions (degrees), one per sample.
    """

    properties: ClassVar[Sequence[str]] = ("watched_motors", "update_freq")
    methods: ClassVar[Sequence[str]] = (*Primitive.methods, "plot")

    def __init__(
        self,
        robot: Robot,
        refresh_freq: float = DEFAULT_UPDATE_HZ,
        watched_motors: MotorList = None,
    ) -> None:
        super().__init__(robot, refresh_freq)
        self.watched_motors = watched_motors
        self.times: list[float] = []
        self.record_positions: dict[str, list[float]] = {}

    @property
    def watched_motors(self) -> list[str]:
        """The motors watched, by name; set a name, a group, a motor or a list of them."""
        return list(self._watched)

    @watched_motors.setter
    def watched_motors(self, value: MotorList) -> None:
        self._watched = _names(self.real_robot, value)

    def setup(self) -> None:
        """Check the motor names and start a new record."""
        _check_motors(self.real_robot, self.watched_motors)
        self.times = []
        self.record_positions = {name: [] for name in self.watched_motors}

    def update(self) -> None:
        """Record one sample."""
        self.times.append(self.elapsed_time)
        for name, positions in self.record_positions.items():
            positions.append(self.robot.motor(name).present_position)

    def plot(self, target: str | Path | Any) -> Any:
        """Draw the recorded positions over time: on a matplotlib axis (pypot's
        ``watcher.plot(ax)``), or into a PNG file.

        Args:
            target: a matplotlib ``Axes`` to draw on, or the image file to write.

        Returns:
            The axis drawn on, or the path written (atomically; an existing regular file is
            replaced).

        Raises:
            FileError: the file cannot be written, or is not a regular file.
        """
        if hasattr(target, "plot") and hasattr(target, "set_xlabel"):
            self._draw(target)
            return target
        from poppy_core.extras import require

        require("matplotlib", extra="plot", feature="plotting")
        import matplotlib

        matplotlib.use("Agg")
        from matplotlib.figure import Figure

        figure = Figure(figsize=(8, 4.5))
        self._draw(figure.add_subplot())
        image = io.BytesIO()
        figure.savefig(image, format="png")
        return write_file(Path(target), image.getvalue(), replace=True)

    def _draw(self, axes: Any) -> None:
        times = list(self.times)
        for name, positions in self.record_positions.items():
            count = min(len(times), len(positions))
            axes.plot(times[:count], positions[:count], label=name)
        axes.set_xlabel("time (s)")
        axes.set_ylabel("present position (°)")
        if self.record_positions:
            axes.legend(loc="upper right")


BUILTINS: dict[str, type[Primitive]] = {
    "sinus": Sinus,
    "cosinus": Cosinus,
    "square": Square,
    "position_watcher": PositionWatcher,
    "simple_posture": SimplePosture,
}
"""Name -> built-in primitive class (each can be built from the robot alone)."""


def attach_builtins(robot: Robot, **overrides: Any) -> dict[str, Primitive]:
    """Attach one instance of every built-in not yet attached, under its ``BUILTINS`` name.

    Args:
        robot: the robot.
        **overrides: name -> a primitive to attach instead of the default instance.

    Returns:
        Name -> the attached primitive (also reachable as ``robot.<name>``).

    Raises:
        ConfigError: an override that is not a primitive of this robot.
    """
    out: dict[str, Primitive] = {}
    for name, cls in BUILTINS.items():
        existing = robot.extensions.get(name)
        if isinstance(existing, Primitive):
            out[name] = existing
            continue
        primitive = overrides.get(name) or cls(robot)
        if not isinstance(primitive, Primitive):
            raise ConfigError(f"{name}: {primitive!r} is not a primitive", field=name)
        attach_primitive(robot, name, primitive)
        out[name] = primitive
    return out
