"""The follower side of ``teleoperate``: the ``Follower`` interface and ``LocalFollower``.

A local robot follows through a ``GoalStream`` (ramp, hold); a robot served by ``poppy serve``
follows through ``poppy_core.remote.RemoteFollower``, which has the same interface.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping, Sequence
from typing import TYPE_CHECKING, Protocol

from poppy_core.motion.teleop.goal_stream import GoalStream, GoalStreamChange

if TYPE_CHECKING:
    from poppy_core.robot import Robot


class Follower(Protocol):
    """What ``teleoperate`` needs of a follower (a ``LocalFollower`` wraps a ``Robot``)."""

    @property
    def motor_names(self) -> list[str]:
        """Every motor the follower has."""
        ...

    @property
    def state(self) -> str:
        """``held``, ``ramping``, ``following``, ``stopped`` (a remote one adds ``link lost``)."""
        ...

    def start(self, motors: Sequence[str]) -> None:
        """Stiffen ``motors`` where they are; the first targets start a ramp."""
        ...

    def send(self, targets: Mapping[str, float]) -> None:
        """New targets (degrees, user frame), written at once."""
        ...

    def hold(self, reason: str) -> None:
        """Hold where the motors are; the next targets start a new ramp."""
        ...

    def positions(self) -> dict[str, float]:
        """The present positions of the motors started (degrees, user frame)."""
        ...

    def stop(self) -> None:
        """Hold where the motors are and end the stream (they stay stiff)."""
        ...


class LocalFollower:
    """A local robot as a follower (a ``GoalStream`` on its motors).

    Args:
        robot: the follower robot.
        ramp_s: duration of the start and resume ramps (None: from the distance).
        on_change: called with each ``GoalStreamChange``.
        clock: monotonic time in seconds.
    """

    def __init__(
        self,
        robot: Robot,
        *,
        ramp_s: float | None = None,
        on_change: Callable[[GoalStreamChange], None] | None = None,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.robot = robot
        self.ramp_s = ramp_s
        self.on_change = on_change
        self._clock = clock
        self.session: GoalStream | None = None

    @property
    def motor_names(self) -> list[str]:
        """Every motor of the robot."""
        return [m.name for m in self.robot.motors]

    @property
    def state(self) -> str:
        """The session's state (``idle`` before ``start``)."""
        return self.session.state if self.session is not None else "idle"

    def start(self, motors: Sequence[str]) -> None:
        """Stiffen ``motors`` where they are."""
        self.session = GoalStream(
            self.robot, motors, ramp_s=self.ramp_s, on_change=self.on_change, clock=self._clock
        )
        self.session.start()

    def send(self, targets: Mapping[str, float]) -> None:
        """Targets, ramped when a ramp runs, written at once."""
        self._session().push(targets)

    def hold(self, reason: str) -> None:
        """Hold where the motors are."""
        self._session().hold(reason)

    def positions(self) -> dict[str, float]:
        """Present positions of the motors started."""
        return self._session().positions()

    def stop(self) -> None:
        """Hold and end the stream."""
        if self.session is not None:
            self.session.stop()

    def _session(self) -> GoalStream:
        if self.session is None:
            raise RuntimeError("the follower was not started")
        return self.session
