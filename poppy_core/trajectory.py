"""Trajectories in one joint: minimum jerk (quintic) and the constant-speed ``dummy`` control.

Pure math (no robot, no threads): ``Robot.goto_position`` samples these at its write rate.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from poppy_core import checks
from poppy_core.errors import ArgumentError

CONTROLS: tuple[str, ...] = ("minjerk", "dummy")
"""The ``control`` names ``goto_position`` accepts."""
CONTROL_SPELLINGS: dict[str, str] = {"minijerk": "minjerk"}
"""Other spellings accepted for a control (the Poppy documentation writes ``'minijerk'``)."""


def control_name(control: str) -> str:
    """The control ``control`` spells (``"minijerk"`` is ``"minjerk"``), checked.

    Raises:
        ArgumentError: not a known control.
    """
    name = CONTROL_SPELLINGS.get(control, control) if isinstance(control, str) else control
    if name not in CONTROLS:
        raise ArgumentError(
            f"control must be one of {', '.join(CONTROLS)}, not {control!r}",
            field="control",
            value=control,
        )
    return name


MAX_DURATION_S = checks.MAX_DURATION_S
"""The longest goto or move (a day): longer is a typing mistake that would never end."""
MIN_DURATION_S = checks.MIN_DURATION_S
"""A goto shorter than this (one period of the fastest loop) is a jump: the goal is sent at once
at full speed, as for 0 (no loop could sample it, and a minimum-jerk curve of 1e-300 s divides
by zero)."""


def clamp_goal(target: float, limits: tuple[float, float] | None) -> float:
    """``target`` clamped to the angle ``limits`` (None: a wheel, no limits).

    The limit rule, written here once (docs/internals.md, "The limit rule"): a finite goal
    beyond the limits is clamped, on every surface (Python's ``Motor.goal_position``, the
    service behind REST, pypot's routes, the WebSocket, Snap!, ZMQ, Zenoh and ROS 2), and the
    answer says where the motor goes where the surface has an answer; a goal that is not a
    finite number is refused before (``checks.number``).
    """
    return target if limits is None else min(max(target, limits[0]), limits[1])


def goto_duration(value: object) -> float:
    """A goto's duration given as a number or as text (a URL segment, a JSON string), checked.

    The one duration rule of every surface (Python, CLI, REST, Snap!, ZMQ): ``checks.duration``.

    Raises:
        ArgumentError: not a number, not finite, negative, between 0 and ``MIN_DURATION_S``, or
            longer than ``MAX_DURATION_S``.
    """
    return checks.duration(checks.number_from(value, "duration"))


def check_goto(duration_s: float, control: str) -> None:
    """Refuse a goto's duration or control before anything moves.

    Raises:
        ArgumentError: unknown ``control``, or a duration that is negative, not finite, longer
            than ``MAX_DURATION_S`` or too short to divide by (``checks.duration``).
    """
    control_name(control)
    checks.duration(duration_s)


def minimum_jerk_weight(fraction: float) -> float:
    """The minimum-jerk blend 10τ³ − 15τ⁴ + 6τ⁵ of ``fraction`` τ (clamped to 0..1).

    The share of the way a rest-to-rest ``MinimumJerk`` has gone at ``fraction`` of its time:
    ramps and straight moves blend with it instead of building the polynomial.
    """
    tau = min(max(fraction, 0.0), 1.0)
    return min(1.0, tau * tau * tau * (10.0 + tau * (-15.0 + 6.0 * tau)))


@dataclass(frozen=True)
class MinimumJerk:
    """A quintic polynomial from ``start`` to ``goal`` in ``duration_s`` seconds.

    It minimises the integral of the squared jerk under the six boundary conditions (position,
    velocity and acceleration at both ends): the classic smooth point-to-point motion. With the
    default zero velocities and accelerations it starts and stops at rest without overshoot.

    Attributes:
        start: position at t = 0 (any unit, usually degrees).
        goal: position at t = ``duration_s``.
        duration_s: length of the motion in seconds (> 0).
        start_velocity, goal_velocity: velocities at both ends (unit/s).
        start_acceleration, goal_acceleration: accelerations at both ends (unit/s²).
    """

    start: float
    goal: float
    duration_s: float
    start_velocity: float = 0.0
    start_acceleration: float = 0.0
    goal_velocity: float = 0.0
    goal_acceleration: float = 0.0
    coefficients: tuple[float, ...] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        values = (
            self.start,
            self.goal,
            self.duration_s,
            self.start_velocity,
            self.start_acceleration,
            self.goal_velocity,
            self.goal_acceleration,
        )
        if not all(math.isfinite(v) for v in values):
            raise ValueError("trajectory boundaries must be finite numbers")
        if self.duration_s <= 0:
            raise ValueError(f"duration must be positive, got {self.duration_s} s")
        t = self.duration_s
        p0, p1 = self.start, self.goal
        v0, v1 = self.start_velocity, self.goal_velocity
        a0, a1 = self.start_acceleration, self.goal_acceleration
        dp = p1 - p0
        # Solving p(T)=p1, p'(T)=v1, p''(T)=a1 for the three upper coefficients of
        # p(t) = c0 + c1 t + c2 t² + c3 t³ + c4 t⁴ + c5 t⁵ with c0=p0, c1=v0, c2=a0/2.
        c3 = (20 * dp - (8 * v1 + 12 * v0) * t - (3 * a0 - a1) * t**2) / (2 * t**3)
        c4 = (-30 * dp + (14 * v1 + 16 * v0) * t + (3 * a0 - 2 * a1) * t**2) / (2 * t**4)
        c5 = (12 * dp - 6 * (v1 + v0) * t - (a0 - a1) * t**2) / (2 * t**5)
        object.__setattr__(self, "coefficients", (p0, v0, a0 / 2, c3, c4, c5))

    def _clamped(self, t_s: float) -> float:
        return min(max(t_s, 0.0), self.duration_s)

    def position(self, t_s: float) -> float:
        """Position at ``t_s`` seconds (held at the ends outside ``[0, duration_s]``)."""
        t = self._clamped(t_s)
        c = self.coefficients
        return c[0] + t * (c[1] + t * (c[2] + t * (c[3] + t * (c[4] + t * c[5]))))

    def velocity(self, t_s: float) -> float:
        """Velocity at ``t_s`` seconds (the end velocities outside ``[0, duration_s]``)."""
        t = self._clamped(t_s)
        c = self.coefficients
        return c[1] + t * (2 * c[2] + t * (3 * c[3] + t * (4 * c[4] + t * 5 * c[5])))

    def acceleration(self, t_s: float) -> float:
        """Acceleration at ``t_s`` seconds (the end accelerations outside the motion)."""
        t = self._clamped(t_s)
        c = self.coefficients
        return 2 * c[2] + t * (6 * c[3] + t * (12 * c[4] + t * 20 * c[5]))

    def evaluate(self, t_s: float) -> tuple[float, float]:
        """``(position, velocity)`` at ``t_s`` seconds."""
        return self.position(t_s), self.velocity(t_s)

    def done(self, t_s: float) -> bool:
        """True once ``t_s`` reaches the end of the motion."""
        return t_s >= self.duration_s


def dummy_speed(start: float, goal: float, duration_s: float) -> float:
    """The constant speed of the ``dummy`` control: distance over duration.

    The goal is set once with this moving speed; the servo's own controller does the rest (a
    small overshoot is possible since it cannot stop instantly).

    Args:
        start: present position.
        goal: target position.
        duration_s: time to get there; 0 or less means "as fast as possible" (returns 0).

    Returns:
        The speed (unit/s, never negative).
    """
    if duration_s <= 0:
        return 0.0
    return abs(goal - start) / duration_s


@dataclass(frozen=True)
class GotoPlan:
    """How one motor makes a goto: a trajectory to sample, or one goal at a constant speed.

    Attributes:
        goal: where the motor ends (the target, clamped to the angle limits).
        trajectory: the minimum-jerk curve whose positions become goals at the write rate; None
            for the ``dummy`` control and for a goto of no duration (send ``goal`` once).
        speed: the moving speed to set first (0: full speed, the trajectory sets the pace).
    """

    goal: float
    trajectory: MinimumJerk | None
    speed: float


def plan_goto(
    start: float,
    target: float,
    duration_s: float,
    control: str,
    limits: tuple[float, float] | None,
    *,
    min_speed: float = 0.0,
) -> GotoPlan:
    """Plan a goto from ``start`` to ``target`` in ``duration_s`` seconds: the one goto of poppy
    (``Motor.goto_position`` and a primitive's mockup motors both run it).

    Args:
        start: where the motion starts (degrees).
        target: where it should end (degrees).
        duration_s: its length; 0 sends the goal at once at full speed (between 0 and 1 ms is
            refused by ``check_goto``: too short to sample, and surely a typing mistake).
        control: ``"minjerk"`` (``"minijerk"``) or ``"dummy"``.
        limits: the angle limits the goal is clamped to; None for a wheel (no limits).
        min_speed: the smallest speed the servo can be given (one register step): a ``dummy``
            goto slower than that is sent at this speed, since 0 would mean full speed.

    Raises:
        ArgumentError: unknown ``control``, a negative, not finite or too long duration.
    """
    name = control_name(control)
    check_goto(duration_s, name)
    goal = clamp_goal(target, limits)
    if name == "dummy" or duration_s == 0:
        speed = dummy_speed(start, goal, duration_s)
        return GotoPlan(goal, None, max(speed, min_speed) if speed else 0.0)
    return GotoPlan(goal, MinimumJerk(start, goal, duration_s), 0.0)
