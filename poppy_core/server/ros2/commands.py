"""ROS 2 commands checked by the robot's rules: joint goals and trajectories, all or nothing.

A command names joints (the motors) with URDF angles in radians. It is refused whole, moving
nothing, when a joint is unknown, a value is not a finite number, a target lies outside the
motor's angle limits, or a motor is compliant (the refusal says to call ``set_compliant``).
A trajectory's points are followed at their ``time_from_start`` by a worker that sets the
goals every sync period, interpolating between points and setting each point itself (at most
one period late); the next trajectory replaces it.
"""

from __future__ import annotations

import bisect
import logging
import threading
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from poppy_core import checks
from poppy_core.errors import ArgumentError, UnknownMotorError
from poppy_core.schedule import Periodic, Worker

if TYPE_CHECKING:
    from poppy_core.robot import Robot
    from poppy_core.server.ros2.joints import UrdfJoints

logger = logging.getLogger(__name__)

MAX_DELAY_S = 60.0
"""How far in the future a trajectory's ``header.stamp`` may start it."""
COMPLIANT_TIP = "call the node's set_compliant service with data: false first"


class CommandRefused(ArgumentError):
    """A ROS 2 command broke a rule; nothing moved."""


@dataclass(frozen=True)
class Plan:
    """A checked trajectory: motors, times from its start (s) and degrees per point."""

    motors: tuple[str, ...]
    times: tuple[float, ...]
    points: tuple[tuple[float, ...], ...]
    start: float
    """``time.monotonic()`` of its ``time_from_start`` 0."""

    def at(self, elapsed: float, first: Sequence[float]) -> tuple[float, ...]:
        """Degrees ``elapsed`` seconds after the start: linear between points, from ``first``
        (the goals when it began) to the first point, holding the last one at the end."""
        times = (0.0, *self.times)
        points = (tuple(first), *self.points)
        if elapsed >= times[-1]:
            return points[-1]
        index = max(1, bisect.bisect_right(times, elapsed))
        t0, t1 = times[index - 1], times[index]
        share = 1.0 if t1 <= t0 else (elapsed - t0) / (t1 - t0)
        a, b = points[index - 1], points[index]
        return tuple(x + (y - x) * share for x, y in zip(a, b, strict=True))

    def step(
        self, elapsed: float, first: Sequence[float], reached: int
    ) -> tuple[tuple[float, ...], int]:
        """The goals of one sync period and the points reached after it: the first point whose
        time has come and that no period set yet, else the position at ``elapsed``. Every
        point is set once, at most one period late (a point between two periods would
        otherwise be cut short); ``reached`` counts the points set before."""
        if reached < len(self.times) and self.times[reached] <= elapsed:
            return self.points[reached], reached + 1
        return self.at(elapsed, first), reached


def _duration(value: Any, field: str) -> float:
    seconds = float(getattr(value, "sec", 0)) + float(getattr(value, "nanosec", 0)) * 1e-9
    return checks.in_range(seconds, 0.0, 24 * 3600.0, field, "s")


class Commands:
    """Checks and applies joint goals and trajectories to ``robot``'s motors."""

    def __init__(self, robot: Robot, joints: UrdfJoints, rate_hz: float) -> None:
        self.robot = robot
        self.joints = joints
        self.period_s = 1.0 / checks.rate(rate_hz, "rate_hz")
        self.refused = 0
        self._plan: Plan | None = None
        self._first: tuple[float, ...] = ()
        self._lock = threading.Lock()
        self._wake = threading.Event()
        self._worker = Worker("ros2-trajectory", self._follow)

    # -- checks ------------------------------------------------------------------------------

    def goals(self, names: Sequence[str], radians: Sequence[Any]) -> dict[str, float]:
        """Motor -> degrees of ``names`` at ``radians``, every rule checked.

        Raises:
            CommandRefused: a broken rule (which one, and what to do).
        """
        if not names:
            raise CommandRefused("the command names no joint", field="name")
        if len(set(names)) != len(names):
            raise CommandRefused("the command names a joint twice", field="name")
        if len(radians) != len(names):
            raise CommandRefused(
                f"{len(names)} joints but {len(radians)} positions", field="position"
            )
        out: dict[str, float] = {}
        for name, value in zip(names, radians, strict=True):
            try:
                motor = self.robot.motor(name)
            except UnknownMotorError:
                known = ", ".join(m.name for m in self.robot.motors)
                raise CommandRefused(
                    f"no joint {name!r} (joints: {known})", field="name", value=name
                ) from None
            rad = checks.number(value, f"{name} position")
            degrees = self.joints.to_motor(name, rad)
            low, high = motor.angle_limit
            if not motor.wheel_mode and not low - 1e-6 <= degrees <= high + 1e-6:
                raise CommandRefused(
                    f"{name} position {rad:.4g} rad ({degrees:.4g} deg) is outside its limits "
                    f"{low:g} to {high:g} deg",
                    field="position",
                    value=rad,
                )
            if motor.compliant:
                raise CommandRefused(f"{name} is compliant: {COMPLIANT_TIP}", field="name")
            out[name] = degrees
        return out

    def plan(self, message: Any, now: float | None = None) -> Plan | None:
        """The checked plan of a trajectory_msgs/JointTrajectory (None: no point, a stop).

        Raises:
            CommandRefused: a broken rule.
        """
        names = list(message.joint_names)
        if not message.points:
            return None
        times: list[float] = []
        points: list[tuple[float, ...]] = []
        for index, point in enumerate(message.points):
            seconds = _duration(point.time_from_start, f"points[{index}].time_from_start")
            if times and seconds < times[-1]:
                raise CommandRefused(
                    f"points[{index}].time_from_start goes back in time", field="time_from_start"
                )
            goals = self.goals(names, list(point.positions))
            times.append(seconds)
            points.append(tuple(goals[n] for n in names))
        monotonic = time.monotonic() if now is None else now
        stamp = message.header.stamp
        wall = float(stamp.sec) + float(stamp.nanosec) * 1e-9
        delay = 0.0
        if wall > 0:
            delay = checks.in_range(
                wall - time.time(), -1e9, MAX_DELAY_S, "header.stamp (from now)", "s"
            )
        return Plan(tuple(names), tuple(times), tuple(points), monotonic + max(0.0, delay))

    # -- actions -----------------------------------------------------------------------------

    def command(self, names: Sequence[str], radians: Sequence[Any]) -> dict[str, float]:
        """Set the goals of a joint command (all or none); it replaces a running trajectory."""
        goals = self.goals(names, radians)
        with self._lock:
            self._plan = None
            for name, degrees in goals.items():
                self.robot.motor(name).goal_position = degrees
        return goals

    def follow(self, message: Any) -> Plan | None:
        """Start following a trajectory (replacing the running one); an empty one stops it."""
        plan = self.plan(message)
        with self._lock:
            self._plan = plan
            if plan is not None:
                self._first = tuple(self.robot.motor(n).goal_position for n in plan.motors)
        if plan is not None:
            self._worker.start()
            self._wake.set()
        return plan

    def stop(self) -> None:
        """Stop following (the motors hold their goals)."""
        with self._lock:
            self._plan = None

    @property
    def following(self) -> bool:
        """True while a trajectory runs."""
        return self._plan is not None

    def close(self) -> None:
        """Stop the worker."""
        self.stop()
        self._wake.set()
        self._worker.close()

    def _follow(self, stopping: threading.Event) -> None:
        schedule = Periodic(self.period_s, time.monotonic())
        following: Plan | None = None
        reached = 0
        while not stopping.is_set():
            with self._lock:
                plan, first = self._plan, self._first
            if plan is not following:
                following, reached = plan, 0
            if plan is None:
                self._wake.wait(0.5)
                self._wake.clear()
                schedule = Periodic(self.period_s, time.monotonic())
                continue
            wait = schedule.next_deadline - time.monotonic()
            if wait > 0 and stopping.wait(wait):
                return
            now = time.monotonic()
            schedule.advance(now)
            elapsed = now - plan.start
            if elapsed < 0:
                continue
            degrees, reached = plan.step(elapsed, first, reached)
            with self._lock:
                if self._plan is not plan:
                    continue
                for name, value in zip(plan.motors, degrees, strict=True):
                    motor = self.robot.motor(name)
                    if motor.compliant:  # made compliant meanwhile: stop, do not fight it
                        logger.warning("ROS 2: trajectory stopped: %s is compliant", name)
                        self._plan = None
                        break
                    motor.goal_position = value
                else:
                    if reached == len(plan.times):
                        self._plan = None
