"""``CalibrationSession``: a guided calibration driven through callbacks (the core never prompts).

The session makes the joints compliant, asks for the reference posture and reads each joint's
zero there, then asks for each joint (or all at once) to be moved through its range while it
records the extremes. Questions go to a ``CalibrationAnswers`` object (the CLI renders them with
Rich; tests script them) and progress to ``on_event``. ``run`` returns a ``Calibration``; nothing
is written until the caller saves it, so a cancelled or interrupted session changes nothing.
``check_calibration`` reads a robot in its posture and reports how far each joint drifted.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol

from poppy_core import checks
from poppy_core.errors import CalibrationCancelled, ConfigError
from poppy_core.robot.calibration import (
    Calibration,
    JointCalibration,
    ReferencePosture,
    reference_posture,
)
from poppy_core.robot.motor_link import link_of
from poppy_core.schedule import Worker

if TYPE_CHECKING:
    from poppy_core.robot.motor import Motor
    from poppy_core.robot.robot import Robot

logger = logging.getLogger(__name__)

MIN_SPAN_DEG = 10.0
"""A joint moved through less than this is asked about (forgotten, or stuck)."""
SUSPICIOUS_OFFSET_DEG = 25.0
"""A zero this far from the current one is asked about (the robot is not in the posture?)."""
DRIFT_TOLERANCE_DEG = 3.0
SAMPLE_PERIOD_S = 0.01
SETTLE_S = 0.1
"""Time for the sync loop to read a robot just made compliant or just put in its posture."""
CANCELLED = "calibration cancelled: nothing was written"


@dataclass(frozen=True)
class CalibrationEvent:
    """Progress of a session, given to ``on_event``.

    Attributes:
        step: ``compliant``, ``zero``, ``joints``, ``joint_done``, ``warning`` or ``done``.
        message: what happened, in words.
        motors: the joints concerned.
        index: the step of the joint steps (from 1), 0 elsewhere.
        total: how many joint steps there are.
    """

    step: str
    message: str
    motors: tuple[str, ...] = ()
    index: int = 0
    total: int = 0


@dataclass(frozen=True)
class JointReading:
    """One joint while it is moved: where it is and the extremes so far (user frame, degrees,
    with the new zero)."""

    motor: str
    current: float
    low: float
    high: float

    @property
    def span(self) -> float:
        """``high - low``."""
        return self.high - self.low


class CalibrationAnswers(Protocol):
    """The questions of a session; each call blocks until the user answered."""

    def posture(self, posture: ReferencePosture, motors: Sequence[str]) -> bool:
        """Show the reference posture; True once the robot is in it, False to cancel."""
        ...

    def move(self, motors: Sequence[str], watch: RangeWatch) -> bool:
        """Ask for ``motors`` to be moved through their whole range (``watch.readings()`` shows
        it live); True when done, False to cancel."""
        ...

    def confirm(self, question: str) -> bool:
        """A yes/no question."""
        ...


def _motor_frame_position(motor: Motor) -> float:
    """The present position as last read, in the motor frame (the frame calibration measures)."""
    return link_of(motor).number("present_position")


class RangeWatch:
    """Samples some joints in a thread and keeps their extremes (motor frame)."""

    def __init__(self, motors: Sequence[Motor], offsets: dict[str, float], period_s: float) -> None:
        self._motors = list(motors)
        self._offsets = offsets
        self._period_s = checks.period(period_s, "sample_period_s")
        self._lock = threading.Lock()
        first = {m.name: _motor_frame_position(m) for m in self._motors}
        self._low = dict(first)
        self._high = dict(first)
        self._current = dict(first)
        # a sampler that fails ends the thread and says so at ``__exit__``: nothing retried
        self._worker = Worker.periodic(
            "calibration range",
            1.0 / self._period_s,
            lambda now: self._sample(),
            retry=(),
            start_s=lambda: time.monotonic() + self._period_s,
        )

    def __enter__(self) -> RangeWatch:
        self._worker.start()
        return self

    def __exit__(self, *_: object) -> None:
        self._worker.stop(2.0)  # a sampler that failed says so here
        self._sample()

    def _sample(self) -> None:
        with self._lock:
            for motor in self._motors:
                if not motor.online:
                    continue
                value = _motor_frame_position(motor)
                self._current[motor.name] = value
                self._low[motor.name] = min(self._low[motor.name], value)
                self._high[motor.name] = max(self._high[motor.name], value)

    def motor_range(self, name: str) -> tuple[float, float]:
        """The motor-frame extremes of joint ``name`` so far."""
        with self._lock:
            return self._low[name], self._high[name]

    def readings(self) -> list[JointReading]:
        """Every joint watched, in the user frame with the new zero."""
        out = []
        with self._lock:
            for motor in self._motors:
                sign = 1.0 if motor.direct else -1.0
                offset = self._offsets[motor.name]
                ends = sorted(
                    sign * v - offset for v in (self._low[motor.name], self._high[motor.name])
                )
                current = sign * self._current[motor.name] - offset
                out.append(JointReading(motor.name, current, ends[0], ends[1]))
        return out


class CalibrationSession:
    """A calibration of some joints of a robot (see the module docstring).

    Args:
        robot: the robot (built from a config: its reference posture comes from there).
        answers: asks the user.
        motors: the joints to calibrate (None: every motor but wheels).
        posture: the reference posture (None: the config's ``calibration.posture``).
        one_at_a_time: ask for each joint's range in turn (False: all joints at once).
        on_event: called with a ``CalibrationEvent`` at each step.
        min_span_deg: a joint moved through less is asked about.
        suspicious_offset_deg: a zero this far from the current one is asked about.

    Raises:
        ConfigError: an unknown motor, or a robot without a config.
    """

    def __init__(
        self,
        robot: Robot,
        answers: CalibrationAnswers,
        motors: Sequence[str] | None = None,
        *,
        posture: ReferencePosture | None = None,
        one_at_a_time: bool = True,
        on_event: Callable[[CalibrationEvent], None] | None = None,
        min_span_deg: float = MIN_SPAN_DEG,
        suspicious_offset_deg: float = SUSPICIOUS_OFFSET_DEG,
        sample_period_s: float = SAMPLE_PERIOD_S,
        settle_s: float = SETTLE_S,
    ) -> None:
        if robot.config is None:
            raise ConfigError(
                "this robot was built by hand: calibrate a robot built from a profile or a config"
            )
        self.robot = robot
        self.answers = answers
        names = (
            list(motors)
            if motors is not None
            else [m.name for m in robot.motors if not m.wheel_mode]
        )
        self.motors: list[Motor] = [robot.motor(n) for n in names]
        self.posture = posture if posture is not None else reference_posture(robot.config)
        self.one_at_a_time = one_at_a_time
        self.on_event = on_event
        self.min_span_deg = min_span_deg
        self.suspicious_offset_deg = suspicious_offset_deg
        self.sample_period_s = sample_period_s
        self.settle_s = settle_s

    def run(self) -> Calibration:
        """Ask, read and return the calibration (nothing is written).

        Raises:
            CalibrationCancelled: the user cancelled.
            PoppyError: the robot cannot be read.
        """
        for motor in self.motors:
            motor.compliant = True
        time.sleep(self.settle_s)
        self._event("compliant", "the joints are compliant: they move freely by hand")
        zeros = self._zeros()
        offsets = {
            m.name: (1.0 if m.direct else -1.0) * zeros[m.name] - self.posture.angle(m.name)
            for m in self.motors
        }
        steps = [[m] for m in self.motors] if self.one_at_a_time else [self.motors]
        ranges: dict[str, tuple[float, float] | None] = {}
        for index, group in enumerate(steps, start=1):
            ranges.update(self._ranges(group, offsets, index, len(steps)))
        joints = {
            m.name: JointCalibration(
                m.name, zeros[m.name], self.posture.angle(m.name), ranges.get(m.name)
            )
            for m in self.motors
        }
        self._event("done", f"{len(joints)} joints calibrated", tuple(joints))
        return Calibration(joints, self.posture)

    # -- steps ---------------------------------------------------------------------------------

    def _zeros(self) -> dict[str, float]:
        names = [m.name for m in self.motors]
        while True:
            if not self.answers.posture(self.posture, names):
                raise CalibrationCancelled(CANCELLED)
            zeros = read_motor_frame(self.robot, self.motors, self.settle_s)
            far = []
            for motor in self.motors:
                sign = 1.0 if motor.direct else -1.0
                offset = sign * zeros[motor.name] - self.posture.angle(motor.name)
                if abs(offset - motor.offset) > self.suspicious_offset_deg:
                    far.append(f"{motor.name} ({offset - motor.offset:+.1f}°)")
            self._event("zero", "zeros read in the reference posture", tuple(names))
            if not far:
                return zeros
            question = (
                f"{', '.join(far)} read far from their current zero: is the robot in the "
                "reference posture? Record these zeros anyway?"
            )
            self._event("warning", question, tuple(names))
            if self.answers.confirm(question):
                return zeros

    def _ranges(
        self, group: list[Motor], offsets: dict[str, float], index: int, total: int
    ) -> dict[str, tuple[float, float] | None]:
        names = tuple(m.name for m in group)
        while True:
            self._event(
                "joints", f"move {', '.join(names)} through the whole range", names, index, total
            )
            with RangeWatch(group, offsets, self.sample_period_s) as watch:
                done = self.answers.move(list(names), watch)
            if not done:
                raise CalibrationCancelled(CANCELLED)
            found = {m.name: watch.motor_range(m.name) for m in group}
            short = [n for n, (low, high) in found.items() if high - low < self.min_span_deg]
            if not short:
                break
            spans = ", ".join(f"{n} ({found[n][1] - found[n][0]:.1f}°)" for n in short)
            question = (
                f"{spans} moved less than {self.min_span_deg:g}°: keep the previous range "
                "(no = move it again)?"
            )
            self._event("warning", question, tuple(short), index, total)
            if self.answers.confirm(question):
                return {n: (None if n in short else found[n]) for n in names}
        self._event("joint_done", f"{', '.join(names)} recorded", names, index, total)
        return dict(found)

    def _event(
        self,
        step: str,
        message: str,
        motors: tuple[str, ...] = (),
        index: int = 0,
        total: int = 0,
    ) -> None:
        logger.debug("calibration %s: %s", step, message)
        if self.on_event is not None:
            self.on_event(CalibrationEvent(step, message, motors, index, total))


def read_motor_frame(robot: Robot, motors: Sequence[Motor], settle_s: float) -> dict[str, float]:
    """Fresh motor-frame positions of ``motors`` (after ``settle_s``, read now).

    Raises:
        PoppyError: the bus cannot be read.
        ConfigError: a motor does not answer.
    """
    time.sleep(settle_s)
    robot.run_loop("present")
    silent = [m.name for m in motors if not m.online]
    if silent:
        raise ConfigError(
            f"{', '.join(silent)} not answering: check the cables and power",
            field="motors",
            value=silent,
        )
    return {m.name: _motor_frame_position(m) for m in motors}


@dataclass(frozen=True)
class JointDrift:
    """How far a joint reads from its reference posture (user frame, degrees)."""

    motor: str
    expected: float
    measured: float
    tolerance: float

    @property
    def drift(self) -> float:
        """``measured - expected``."""
        return self.measured - self.expected

    @property
    def ok(self) -> bool:
        """True within the tolerance."""
        return abs(self.drift) <= self.tolerance


def check_calibration(
    robot: Robot,
    answers: CalibrationAnswers,
    motors: Sequence[str] | None = None,
    *,
    posture: ReferencePosture | None = None,
    tolerance_deg: float = DRIFT_TOLERANCE_DEG,
    settle_s: float = SETTLE_S,
) -> list[JointDrift]:
    """Read a robot put in its reference posture and compare each joint to what it should read.

    Args:
        robot: the robot (its config gives the posture and the calibration checked).
        answers: asks for the posture (``answers.posture``).
        motors: the joints to check (None: every motor but wheels).
        posture: the reference posture (None: the config's).
        tolerance_deg: a joint further than this has drifted.

    Raises:
        CalibrationCancelled: the user cancelled.
        ConfigError: a robot without a config, an unknown or silent motor.
    """
    if robot.config is None:
        raise ConfigError("this robot was built by hand: it has no calibration to check")
    chosen = (
        [robot.motor(n) for n in motors]
        if motors is not None
        else [m for m in robot.motors if not m.wheel_mode]
    )
    reference = posture if posture is not None else reference_posture(robot.config)
    for motor in chosen:
        motor.compliant = True
    if not answers.posture(reference, [m.name for m in chosen]):
        raise CalibrationCancelled("check cancelled")
    read_motor_frame(robot, chosen, settle_s)
    return [
        JointDrift(m.name, reference.angle(m.name), m.present_position, tolerance_deg)
        for m in chosen
    ]
