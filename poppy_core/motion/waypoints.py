"""``Waypoints`` and ``WaypointFollower``: goals due at times from a start, followed at a rate.

A trajectory of timed points (ROS 2's ``trajectory_msgs/JointTrajectory``, once its joints are
motors and its radians degrees) is followed by one worker that sets the goals every period:
linear between points, from the goals the motors had when it began to the first point, every
point set once and at most one period late (a point between two periods would otherwise be cut
short), the last one held. The next trajectory replaces the running one; a motor made
compliant meanwhile ends it (the follower never fights a hand). The points are goals already
checked (the service's rule: finite, clamped to the angle limits).
"""

from __future__ import annotations

import bisect
import logging
import threading
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

from poppy_core import checks
from poppy_core.schedule import Periodic, Worker

if TYPE_CHECKING:
    from poppy_core.robot import Robot

logger = logging.getLogger(__name__)


@dataclass(frozen=True)
class Waypoints:
    """Motors, the times of the points from the start (s, not decreasing) and degrees per point.

    Attributes:
        start: ``time.monotonic()`` of time 0 (None: when the follower takes it).
    """

    motors: tuple[str, ...]
    times: tuple[float, ...]
    points: tuple[tuple[float, ...], ...]
    start: float | None = None

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
        """The goals of one period and the points reached after it: the first point whose time
        has come and that no period set yet, else the position at ``elapsed`` (``reached``
        counts the points set before)."""
        if reached < len(self.times) and self.times[reached] <= elapsed:
            return self.points[reached], reached + 1
        return self.at(elapsed, first), reached


class WaypointFollower:
    """Follows one ``Waypoints`` at a time on ``robot``'s motors, every ``1 / rate_hz`` s."""

    def __init__(self, robot: Robot, rate_hz: float, name: str = "waypoints") -> None:
        self.robot = robot
        self.period_s = 1.0 / checks.rate(rate_hz, "rate_hz")
        self._plan: Waypoints | None = None
        self._first: tuple[float, ...] = ()
        self._lock = threading.Lock()
        self._wake = threading.Event()
        self._worker = Worker(name, self._follow)

    def follow(self, waypoints: Waypoints) -> Waypoints:
        """Follow ``waypoints`` (replacing the running ones) from where the goals are now; the
        waypoints followed (given a start time when they had none)."""
        if waypoints.start is None:
            waypoints = Waypoints(
                waypoints.motors, waypoints.times, waypoints.points, time.monotonic()
            )
        with self._lock:
            self._plan = waypoints
            self._first = tuple(self.robot.motor(n).goal_position for n in waypoints.motors)
        self._worker.start()
        self._wake.set()
        return waypoints

    def stop(self) -> bool:
        """Stop following (the motors hold their goals); True when something was followed."""
        with self._lock:
            was, self._plan = self._plan is not None, None
        return was

    @property
    def following(self) -> bool:
        """True while waypoints are followed."""
        return self._plan is not None

    @property
    def current(self) -> Waypoints | None:
        """The waypoints followed now (None once they ran out or were stopped)."""
        return self._plan

    def close(self) -> None:
        """Stop and end the worker."""
        self.stop()
        self._wake.set()
        self._worker.close()

    def _follow(self, stopping: threading.Event) -> None:
        schedule = Periodic(self.period_s, time.monotonic())
        following: Waypoints | None = None
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
            assert plan.start is not None  # set by follow()
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
                        logger.warning("the trajectory stopped: %s is compliant", name)
                        self._plan = None
                        break
                    motor.goal_position = value
                else:
                    if reached == len(plan.times):
                        self._plan = None
