"""Hand: moves emulated motors as a person's hand moves a servo's horn (teleop, record, calibrate).

A hand *holds* a motor at an angle (the motor's own angle, as its position registers read) and
keeps holding it, where a gesture left it, until :meth:`Hand.release`. What the motor does is the
plant's business (see ``VirtualMotor.hold_by_hand``); with the ideal servo:

- compliant (torque off): the horn follows the hand, the goal is untouched, the present load
  shows a small effort while it moves; once released it stays where it was left (friction);
- stiff (torque on): the horn resists, it stays at its goal and the present load rises toward
  the torque limit as the hand pushes further; once released the load falls back to 0.

Gestures run in a small thread that exists only while one is under way: ``move`` (a
minimum-jerk or linear path over some seconds) and ``play`` (timed positions, e.g. a move file
turned into motor angles by the caller, which knows the robot's frames).
"""

from __future__ import annotations

import logging
import math
import threading
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Protocol

import numpy as np
import numpy.typing as npt

from poppy_core import checks
from poppy_core.emulator.motor import VirtualMotor
from poppy_core.errors import ArgumentError
from poppy_core.schedule import Ticker, Worker
from poppy_core.trajectory import minimum_jerk_weight

logger = logging.getLogger(__name__)

PERIOD_S = 0.01
"""How often a gesture moves the hand (100 Hz: smoother than any sync loop reads it)."""
PROFILES: tuple[str, ...] = ("minjerk", "linear")
MAX_GESTURE_S = 3600.0
"""The longest gesture (an hour): a typo such as ``--over 1e9`` is refused, not run forever."""


class HandBus(Protocol):
    """What a hand needs of a bus (a ``VirtualBus``): its motors and a way to step its plant."""

    @property
    def motors(self) -> list[VirtualMotor]: ...

    def motor(self, motor_id: int) -> VirtualMotor: ...

    def advance(self, dt_s: float | None = None) -> None: ...


@dataclass
class _Gesture:
    """One motor's path: ``path(t)`` degrees from ``start`` until ``start + duration_s``."""

    path: Callable[[float], float]
    start: float
    duration_s: float

    def at(self, now: float) -> tuple[float, float]:
        """Degrees and deg/s at ``now`` (the speed from the path around that time)."""
        t = min(max(now - self.start, 0.0), self.duration_s)
        if self.duration_s == 0.0 or t >= self.duration_s:
            return self.path(self.duration_s), 0.0
        h = min(PERIOD_S, self.duration_s) / 2
        low, high = max(t - h, 0.0), min(t + h, self.duration_s)
        return self.path(t), (self.path(high) - self.path(low)) / (high - low)

    def done(self, now: float) -> bool:
        return now - self.start >= self.duration_s


class Hand:
    """A hand on the motors of one or more emulated buses (motors named by their ids; of
    motors sharing an id, the first one found).

    Args:
        buses: the buses whose motors the hand can reach.
        period_s: the gestures' step.
        clock: monotonic clock in seconds.
    """

    def __init__(
        self,
        *buses: HandBus,
        period_s: float = PERIOD_S,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.buses = list(buses)
        self._period_s = checks.period(period_s, "period_s")
        self._clock = clock
        self._cond = threading.Condition()
        self._gestures: dict[int, _Gesture] = {}
        self._worker: Worker | None = None
        self._running = False  # the thread runs gestures (set and cleared under the condition)

    # ------------------------------------------------------------------ motors

    def motor(self, motor_id: int) -> VirtualMotor:
        """The motor with id ``motor_id``.

        Raises:
            KeyError: no bus of the hand has it (the message lists the ids).
        """
        for bus in self.buses:
            try:
                return bus.motor(motor_id)
            except KeyError:
                continue
        raise KeyError(f"no motor {motor_id} (motors: {', '.join(map(str, self.ids))})")

    @property
    def ids(self) -> list[int]:
        """The ids of every motor the hand can reach, sorted."""
        return sorted(m.id for bus in self.buses for m in bus.motors)

    def where(self) -> dict[int, float]:
        """Every motor's present position in degrees (the plants stepped to now)."""
        for bus in self.buses:
            bus.advance()
        return {m.id: m.present_position_deg for bus in self.buses for m in bus.motors}

    def holding(self) -> dict[int, float]:
        """The motors the hand holds and where it holds them (degrees)."""
        return {
            m.id: m.hand_deg for bus in self.buses for m in bus.motors if m.hand_deg is not None
        }

    # ------------------------------------------------------------------ gestures

    def move(
        self, motor_id: int, degrees: float, over_s: float = 0.0, profile: str = "minjerk"
    ) -> None:
        """Move the horn of ``motor_id`` to ``degrees`` over ``over_s`` seconds, then hold it.

        The path starts where the hand holds the motor, or at its present position.

        Raises:
            KeyError: an unknown motor.
            ArgumentError: a value that is not finite, a duration out of 0-3600 s, an unknown
                profile (``minjerk`` or ``linear``).
        """
        motor = self.motor(motor_id)
        target = _finite(degrees, "degrees")
        duration = _duration(over_s)
        if profile not in PROFILES:
            raise ArgumentError(
                f"unknown profile {profile!r} (expected {' or '.join(PROFILES)})", field="profile"
            )
        start = motor.hand_deg
        if start is None:
            self.where()
            start = motor.present_position_deg
        weight = minimum_jerk_weight if profile == "minjerk" else _linear

        def path(t: float, a: float = start, b: float = target) -> float:
            return b if duration == 0.0 else a + (b - a) * weight(t / duration)

        self._begin({motor_id: path}, duration)

    def play(
        self,
        times_s: npt.ArrayLike,
        positions: Mapping[int, npt.ArrayLike],
        speed: float = 1.0,
    ) -> float:
        """Move motors through timed positions (linearly between them), then hold the last ones.

        Args:
            times_s: increasing times of the frames, from 0.
            positions: motor id -> one angle (degrees) per frame.
            speed: how much faster than written (0.5: twice as slow).

        Returns:
            How long the gesture lasts, in seconds.

        Raises:
            KeyError: an unknown motor.
            ArgumentError: no frame, times not increasing, a column of the wrong length, a
                speed that is not positive, a gesture longer than an hour.
        """
        times = np.asarray(times_s, dtype=float)
        rate = _finite(speed, "speed")
        if rate <= 0:
            raise ArgumentError(f"speed must be positive, not {speed:g}", field="speed")
        if times.ndim != 1 or len(times) == 0 or np.any(np.diff(times) < 0):
            raise ArgumentError("play needs frames at increasing times", field="times")
        for motor_id in positions:
            self.motor(motor_id)
        columns = {i: np.asarray(v, dtype=float) for i, v in positions.items()}
        if any(c.shape != times.shape or not np.all(np.isfinite(c)) for c in columns.values()):
            raise ArgumentError(
                "play needs one finite angle per frame and motor", field="positions"
            )
        scaled = (times - times[0]) / rate
        duration = _duration(float(scaled[-1]))

        def path_of(column: np.ndarray) -> Callable[[float], float]:
            return lambda t: float(np.interp(t, scaled, column))

        self._begin({i: path_of(c) for i, c in columns.items()}, duration)
        return duration

    def release(self, motor_id: int | None = None) -> list[int]:
        """Let go of ``motor_id`` (every motor when None); returns the ids let go of.

        Raises:
            KeyError: an unknown motor.
        """
        motors = [self.motor(motor_id)] if motor_id is not None else self._all()
        with self._cond:
            for motor in motors:
                self._gestures.pop(motor.id, None)
        released = []
        for motor in motors:
            if motor.hand_deg is not None:
                released.append(motor.id)
            motor.hold_by_hand(None)
        self._advance()
        return released

    def busy(self) -> bool:
        """True while a gesture is under way."""
        with self._cond:
            return bool(self._gestures)

    def wait(self, timeout_s: float | None = None) -> bool:
        """Wait until every gesture is done; False when ``timeout_s`` ran out first."""
        with self._cond:
            return self._cond.wait_for(lambda: not self._gestures, timeout_s)

    def close(self) -> None:
        """Stop the gestures and let go of every motor."""
        with self._cond:
            self._gestures.clear()
            self._cond.notify_all()
            worker, self._worker = self._worker, None
        if worker is not None:
            worker.close(2.0)
        with self._cond:
            self._running = False
        for motor in self._all():
            motor.hold_by_hand(None)

    def __enter__(self) -> Hand:
        return self

    def __exit__(self, *_: object) -> None:
        self.close()

    # ------------------------------------------------------------------ the thread

    def _all(self) -> list[VirtualMotor]:
        return [m for bus in self.buses for m in bus.motors]

    def _begin(self, paths: Mapping[int, Callable[[float], float]], duration_s: float) -> None:
        now = self._clock()
        with self._cond:
            for motor_id, path in paths.items():
                self._gestures[motor_id] = _Gesture(path, now, duration_s)
            self._apply(now)
            if self._gestures and not self._running:
                if self._worker is not None:
                    self._worker.close(2.0)  # it has returned (or is returning) already
                self._running = True
                self._worker = Worker("emulator hand", self._run)
                self._worker.start()

    def _apply(self, now: float) -> None:
        """Put every gesture's motor where its path is at ``now`` (under the condition)."""
        for motor_id, gesture in list(self._gestures.items()):
            self.motor(motor_id).hold_by_hand(*gesture.at(now))
            if gesture.done(now):
                del self._gestures[motor_id]
        self._advance()
        if not self._gestures:
            self._cond.notify_all()

    def _advance(self) -> None:
        for bus in self.buses:
            bus.advance()

    def _tick(self, now: float) -> bool:
        with self._cond:
            if not self._gestures:
                self._running = False
                return False
            self._apply(self._clock())
            return True

    def _run(self, stopping: threading.Event) -> None:
        # a gesture that raises ends them all: nothing retried
        ticker = Ticker("emulator hand", 1.0 / self._period_s, self._tick, retry=())
        try:
            ticker.run(stopping)
        except BaseException:
            with self._cond:  # the gestures stop with the thread (Worker logs the error)
                self._running = False
                self._gestures.clear()
                self._cond.notify_all()
            raise


def _linear(fraction: float) -> float:
    return min(max(fraction, 0.0), 1.0)


def _finite(value: float, what: str) -> float:
    number = float(value)
    if not math.isfinite(number):
        raise ArgumentError(f"{what} must be a finite number, not {value!r}", field=what)
    return number


def _duration(value: float) -> float:
    seconds = _finite(value, "seconds")
    if not 0.0 <= seconds <= MAX_GESTURE_S:
        raise ArgumentError(
            f"a gesture lasts 0-{MAX_GESTURE_S:g} s, not {value:g}", field="seconds"
        )
    return seconds
