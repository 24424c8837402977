"""The sandbox a primitive sees: mockup motors whose writes are requests for the manager.

Inside a primitive, ``self.robot.m1.goal_position = 10`` does not touch the motor: it records a
request in that primitive's ``MockupMotor``. The ``PrimitiveManager`` collects the requests of
every running primitive, combines them and writes the result to the real motor. Reads that are
not requests (``present_position``, ``angle_limit``...) go straight to the real motor.
"""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Callable, Iterable, Mapping
from typing import TYPE_CHECKING, Any

from poppy_core.errors import RegisterError, UnknownMotorError
from poppy_core.trajectory import MinimumJerk, check_goto, plan_goto

if TYPE_CHECKING:
    from poppy_core.robot import Motor, Robot

NUMERIC_REGISTERS: tuple[str, ...] = ("goal_position", "moving_speed", "torque_limit")
"""Requests the manager combines with its filter (mean, sum...)."""
STATE_REGISTERS: tuple[str, ...] = ("compliant", "led")
"""Requests where the most recently started primitive wins (a mean of on/off makes no sense)."""
REQUESTABLE: tuple[str, ...] = (*NUMERIC_REGISTERS, *STATE_REGISTERS)
PASSED_THROUGH: tuple[str, ...] = ("pid", "compliance_margin", "compliance_slope")
"""Servo settings a primitive writes to the motor at once (pypot's manager set them from the
request; there is nothing to combine: poppy-humanoid's StandPosition sets ``m.pid``)."""
_ALIASES = {"max_torque": "torque_limit"}
_OWN = frozenset({"_motor", "_lock", "_requests", "_trajectory", "_stopped", "_clock"})

Requests = dict[str, dict[str, Any]]
"""Motor name -> register -> requested value."""


def _number(motor: str, register: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise RegisterError(
            f"{motor}: {register} takes a number, not {value!r}", register=register, motor=motor
        )
    number = float(value)
    if not math.isfinite(number):
        raise RegisterError(
            f"{motor}: {register} must be finite, got {value}", register=register, motor=motor
        )
    return number


class _Trajectory:
    """A minimum-jerk goto running inside a mockup motor (sampled when the manager asks)."""

    def __init__(self, curve: MinimumJerk, t0: float) -> None:
        self.curve = curve
        self.t0 = t0


class MockupMotor:
    """A motor as a primitive sees it: writes become requests, reads reach the real motor.

    Args:
        motor: the real motor.
        stopped: the owning primitive's stop event (``goto_position(wait=True)`` returns early
            when it is set).
        clock: time source of the gotos.
    """

    _motor: Motor
    _lock: threading.Lock
    _requests: dict[str, Any]
    _trajectory: _Trajectory | None
    _stopped: threading.Event
    _clock: Callable[[], float]

    def __init__(
        self,
        motor: Motor,
        stopped: threading.Event | None = None,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        object.__setattr__(self, "_motor", motor)
        object.__setattr__(self, "_lock", threading.Lock())
        object.__setattr__(self, "_requests", {})
        object.__setattr__(self, "_trajectory", None)
        object.__setattr__(self, "_stopped", stopped or threading.Event())
        object.__setattr__(self, "_clock", clock)

    def __repr__(self) -> str:
        return f"<MockupMotor {self._motor.name} requests={self.requests()}>"

    @property
    def real_motor(self) -> Motor:
        """The motor behind this mockup (writing to it bypasses the manager)."""
        return self._motor

    # -- reads and writes -------------------------------------------------------------------

    def __getattr__(self, name: str) -> Any:
        # Only called when normal lookup fails: a request of ours, else the real motor's value.
        if name.startswith("_"):
            raise AttributeError(name)
        register = _ALIASES.get(name, name)
        if register == "goal_position":
            return self._requested_goal()
        with self._lock:
            if register in self._requests:
                return self._requests[register]
        return getattr(self._motor, name)

    def __setattr__(self, name: str, value: Any) -> None:
        if name in _OWN:
            object.__setattr__(self, name, value)
            return
        if name == "goal_speed":
            self._request_speed(_number(self._motor.name, name, value))
            return
        if name in PASSED_THROUGH:
            setattr(self._motor, name, value)
            return
        register = _ALIASES.get(name, name)
        if register not in REQUESTABLE:
            raise RegisterError(
                f"{self._motor.name}: a primitive may request only "
                f"{', '.join(REQUESTABLE)} or goal_speed (and set "
                f"{', '.join(PASSED_THROUGH)}), not {name!r}",
                register=name,
                motor=self._motor.name,
            )
        checked = self._checked(register, value)
        with self._lock:
            if register == "goal_position":
                self._trajectory = None
            self._requests[register] = checked

    def _checked(self, register: str, value: Any) -> Any:
        motor = self._motor
        if register == "compliant":
            if not isinstance(value, bool | int):
                raise RegisterError(
                    f"{motor.name}: compliant takes True or False",
                    register=register,
                    motor=motor.name,
                )
            return bool(value)
        if register == "led":
            motor.model.register("led").from_si(value)  # raises RegisterError when invalid
            return value
        number = _number(motor.name, register, value)
        if register == "moving_speed" and number < 0:
            raise RegisterError(
                f"{motor.name}: moving_speed is a magnitude (>= 0), got {value}",
                register=register,
                motor=motor.name,
            )
        if register == "torque_limit":
            if not motor.model.has_torque_limit:
                raise RegisterError(
                    f"{motor.name}: {motor.model.name} has no torque limit register",
                    register=register,
                    motor=motor.name,
                )
            if not 0.0 <= number <= 100.0:
                raise RegisterError(
                    f"{motor.name}: torque_limit is 0..100 %, got {value}",
                    register=register,
                    motor=motor.name,
                )
        return number

    def _requested_goal(self) -> float:
        with self._lock:
            trajectory = self._trajectory
            if trajectory is not None:
                return trajectory.curve.position(self._clock() - trajectory.t0)
            if "goal_position" in self._requests:
                return float(self._requests["goal_position"])
        return float(self._motor.goal_position)

    def _request_speed(self, speed_dps: float) -> None:
        # Same idea as Motor.goal_speed: head for the limit in that direction at |speed|.
        if abs(speed_dps) < 1e-6:
            self.goal_position = self._motor.present_position
            return
        low, high = self._motor.angle_limit
        magnitude = min(abs(speed_dps), self._motor.model.no_load_speed_dps)
        with self._lock:
            self._trajectory = None
            self._requests["moving_speed"] = magnitude
            self._requests["goal_position"] = high if speed_dps > 0 else low

    # -- gotos -------------------------------------------------------------------------------

    def goto_position(
        self, position: float, duration: float, control: str = "minjerk", wait: bool = False
    ) -> None:
        """Request a move to ``position`` (degrees) in ``duration`` seconds.

        Args:
            position: the target, clamped to the motor's angle limits.
            duration: seconds to get there.
            control: ``"minjerk"`` (the goal follows a smooth trajectory) or ``"dummy"`` (one
                goal with the constant moving speed that arrives on time).
            wait: block until the duration elapsed (or the primitive is stopped).

        Raises:
            ArgumentError: unknown control, a negative or not finite duration.
        """
        check_goto(duration, control)  # before the position: the error a caller expects first
        motor = self._motor
        target = _number(motor.name, "goal_position", position)
        start = self._requested_goal() if self._has_goal() else motor.present_position
        plan = plan_goto(
            start,
            target,
            duration,
            control,
            motor.angle_limit,
            min_speed=abs(float(motor.model.register("moving_speed").to_si(1))),
        )
        if plan.trajectory is None:
            self.moving_speed = plan.speed
            self.goal_position = plan.goal
        else:
            with self._lock:
                self._requests["moving_speed"] = plan.speed
                self._requests.pop("goal_position", None)
                self._trajectory = _Trajectory(plan.trajectory, self._clock())
        if wait:
            self._stopped.wait(duration)

    def _has_goal(self) -> bool:
        with self._lock:
            return self._trajectory is not None or "goal_position" in self._requests

    # -- for the manager ---------------------------------------------------------------------

    def requests(self, now: float | None = None) -> dict[str, Any]:
        """The values this primitive requests now (a running goto is sampled at ``now``)."""
        with self._lock:
            out = dict(self._requests)
            trajectory = self._trajectory
        if trajectory is not None:
            t = (self._clock() if now is None else now) - trajectory.t0
            out["goal_position"] = trajectory.curve.position(t)
        return out

    def clear(self) -> None:
        """Drop every request (a restarted primitive starts clean)."""
        with self._lock:
            self._requests.clear()
            self._trajectory = None


class MockupRobot:
    """A robot as a primitive sees it: mockup motors and groups, everything else read-through.

    Args:
        robot: the real robot.
        stopped: the owning primitive's stop event.
    """

    def __init__(self, robot: Robot, stopped: threading.Event | None = None) -> None:
        self._robot = robot
        self._stopped = stopped or threading.Event()
        self._motors = {m.name: MockupMotor(m, self._stopped) for m in robot.motors}

    def __repr__(self) -> str:
        return f"<MockupRobot motors={list(self._motors)}>"

    def __getattr__(self, name: str) -> Any:
        # Only called when normal lookup fails: motors, groups, then the real robot.
        if name.startswith("_"):
            raise AttributeError(name)
        motors = self.__dict__.get("_motors", {})
        if name in motors:
            return motors[name]
        groups = self._robot.motorgroups
        if name in groups:
            return [motors[m.name] for m in groups[name]]
        return getattr(self._robot, name)

    def __dir__(self) -> list[str]:
        return sorted({*super().__dir__(), *dir(self._robot)})

    @property
    def real_robot(self) -> Robot:
        """The robot behind this sandbox (writing to it bypasses the manager)."""
        return self._robot

    @property
    def motors(self) -> list[MockupMotor]:
        """Every mockup motor, in the robot's order."""
        return list(self._motors.values())

    def motor(self, name: str) -> MockupMotor:
        """The mockup of motor ``name``.

        Raises:
            UnknownMotorError: no such motor (a ``ConfigError``).
        """
        if name not in self._motors:
            known = list(self._motors)
            raise UnknownMotorError(
                f"no motor {name!r} (motors: {', '.join(known)})", motor=str(name), known=known
            )
        return self._motors[name]

    def mockup(self, motor: Motor | MockupMotor | str) -> MockupMotor:
        """The mockup of a real motor, a mockup, or a motor name (pypot's ``get_mockup_motor``)."""
        name = motor if isinstance(motor, str) else motor.name
        return self.motor(name)

    def goal_motors(self) -> list[str]:
        """The motors this sandbox asks a goal position of (a running goto included)."""
        return [name for name, motor in self._motors.items() if motor._has_goal()]

    @property
    def compliant(self) -> bool:
        """True when every motor is (as requested, else really) compliant."""
        return all(m.compliant for m in self._motors.values())

    @compliant.setter
    def compliant(self, value: bool) -> None:
        for motor in self._motors.values():
            motor.compliant = value

    def goto_position(
        self,
        position_for_motors: Mapping[str, float],
        duration: float,
        control: str = "minjerk",
        wait: bool = False,
    ) -> None:
        """Request several motors to move so that they arrive together.

        Raises:
            UnknownMotorError: an unknown motor name (a ``ConfigError``).
        """
        targets = [(self.motor(name), pos) for name, pos in position_for_motors.items()]
        for motor, position in targets:
            motor.goto_position(position, duration, control)
        if wait:
            self._stopped.wait(duration)

    def requests(self, now: float | None = None) -> Requests:
        """Motor name -> the values requested now (motors without requests left out)."""
        out: Requests = {}
        for name, motor in self._motors.items():
            values = motor.requests(now)
            if values:
                out[name] = values
        return out

    def clear(self, names: Iterable[str] | None = None) -> None:
        """Drop the requests of the named motors (all when None)."""
        for name in self._motors if names is None else names:
            self._motors[name].clear()
