"""A chain's straight move (``goto_linear``): its waypoints planned, then streamed in a thread."""

from __future__ import annotations

import contextlib
import math
import threading
from collections.abc import Callable
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np

from poppy_core.errors import KinematicsError, PortError
from poppy_core.kinematics import Chain, make_target
from poppy_core.kinematics.chain import Orientation
from poppy_core.kinematics.transforms import Matrix, Vector, axis_angle_matrix, rotation_log
from poppy_core.schedule import Ticker, Worker
from poppy_core.trajectory import minimum_jerk_weight

if TYPE_CHECKING:
    from poppy_core.robot import Robot

MAX_LINEAR_JUMP_DEG = 15.0
"""Largest joint change between two waypoints of a straight line (a jump means a flip)."""


def plan_line(
    model: Chain,
    start: Matrix,
    present: Callable[[], dict[str, float]],
    name: str,
    position: Vector,
    orientation: Orientation,
    count: int,
) -> list[dict[str, float]]:
    """Joint angles of ``count`` points from the present tip pose to the target on a line.

    The tip follows minimum-jerk timing along the segment; the orientation (when asked) turns
    about one axis from the present one to the target.

    Args:
        model: the chain's kinematic model.
        start: the tip's present pose (4x4).
        present: reads the chain's motors' present positions (degrees), the solves' seed.
        name: the chain's name, for the errors.
        position: the target ``[x, y, z]`` (metres).
        orientation: None, the tip's x axis, or a 3x3 rotation matrix.
        count: how many points, the present one included.
    """
    target = make_target(position, orientation, name)
    model.solve(position, orientation, present())  # an unreachable end is said first, as goto
    seeded_only = replace(model.options, restarts=0)
    begin = start[:3, 3]
    seed: dict[str, float] = present()
    waypoints: list[dict[str, float]] = []
    turn = None
    if target.mode == "all":
        assert target.orientation is not None
        turn = rotation_log(target.orientation @ start[:3, :3].T)
    elif target.mode == "x":
        assert target.orientation is not None
        axis = np.cross(start[:3, 0], target.orientation)
        angle = math.atan2(float(np.linalg.norm(axis)), float(start[:3, 0] @ target.orientation))
        turn = axis / (np.linalg.norm(axis) or 1.0) * angle
    for k in range(1, count):
        tau = k / (count - 1)
        s = minimum_jerk_weight(tau)
        point = begin + s * (target.position - begin)
        goal: Matrix | None = None
        if turn is not None:
            angle = float(np.linalg.norm(turn))
            rotation = axis_angle_matrix(turn, s * angle) if angle > 0 else np.eye(3)
            goal = rotation @ start[:3, :3] if target.mode == "all" else rotation @ start[:3, 0]
        try:
            angles = model.solve(point, goal, seed, options=seeded_only)
        except KinematicsError as exc:
            where = ", ".join(f"{v:.3f}" for v in point)
            try:
                model.solve(point, goal, seed)
            except KinematicsError:
                raise KinematicsError(
                    f"the straight line leaves the reach of chain {name!r} at ({where}) m: "
                    f"the nearest point there is {exc.distance_m or 0.0:.3f} m off; "
                    "use goto, or a waypoint in between",
                    chain=name,
                    target=exc.target,
                    nearest=exc.nearest,
                    distance_m=exc.distance_m,
                ) from None
            raise KinematicsError(
                f"chain {name!r} cannot follow the straight line near ({where}) m without "
                "turning its joints around; use goto, or a waypoint in between",
                chain=name,
            ) from None
        jump = max(abs(angles[n] - seed[n]) for n in angles)
        if jump > MAX_LINEAR_JUMP_DEG:
            raise KinematicsError(
                f"chain {name!r} cannot follow the straight line smoothly: its joints "
                f"would jump {jump:.0f}° near ({', '.join(f'{v:.3f}' for v in point)}) m; "
                "use goto, or a waypoint in between",
                chain=name,
            )
        seed = {**seed, **angles}
        waypoints.append(angles)
    return waypoints


class LinearMove:
    """Streams the waypoints of a straight move, one short goto per period, in its own thread.

    A failure ends the move: logged once, kept in ``error`` and raised by ``wait``.
    """

    def __init__(
        self, robot: Robot, waypoints: list[dict[str, float]], period_s: float, name: str
    ) -> None:
        self._robot = robot
        self._waypoints = waypoints
        self._period_s = period_s
        self.duration_s = period_s * len(waypoints)
        self._worker = Worker(f"goto_linear {name}", self._run)
        self._worker.start()

    @property
    def error(self) -> BaseException | None:
        """What ended the move early (None: it ran to its end, was cancelled, the robot closed)."""
        return self._worker.error

    @property
    def done(self) -> bool:
        """True once the move ended (or was cancelled)."""
        return not self._worker.running

    def wait(self, timeout_s: float | None = None) -> bool:
        """Block until the move ends; False when ``timeout_s`` ran out first.

        Raises:
            Exception: what ended the move early (``error``).
        """
        return self._worker.join(timeout_s)

    def cancel(self) -> None:
        """Stop streaming waypoints (motors finish their current short goto)."""
        self._worker.request_stop()

    def _run(self, cancel: threading.Event) -> None:
        # a late waypoint goes at once and the next keep their times (no deadline is skipped);
        # a waypoint that raises ends the move (``wait()`` raises it): nothing retried
        waypoints = iter(self._waypoints)

        def send(now: float) -> bool:
            angles = next(waypoints, None)
            if angles is None:
                return False
            # dummy control: each motor gets the next waypoint and the speed to reach it in
            # one period, so the servos move continuously between waypoints
            self._robot.goto_position(angles, self._period_s, control="dummy")
            return True

        ticker = Ticker(
            self._worker.name, 1.0 / self._period_s, send, catch_up=len(self._waypoints), retry=()
        )
        with contextlib.suppress(PortError):  # the robot closed under the move
            ticker.run(cancel)
