"""Goto runner: steps minimum-jerk trajectories into goal positions from one on-demand thread.

The thread starts with the first motion and ends when no motion is left, so an idle robot (or
a lone ``Motor``) holds no goto thread. A new goto on a motor replaces the one it was doing.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from typing import TypeVar

from poppy_core.errors import RobotClosedError
from poppy_core.robot.goto_handle import GotoHandle as GotoHandle
from poppy_core.robot.motor_link import GotoTarget, link_of
from poppy_core.schedule import Worker
from poppy_core.trajectory import MinimumJerk, check_goto, control_name, plan_goto

logger = logging.getLogger(__name__)

DEFAULT_RATE_HZ = 50.0


_Target = TypeVar("_Target", bound=GotoTarget)


@dataclass
class _Move:
    motor: GotoTarget
    goal: float
    trajectory: MinimumJerk | None
    t0: float
    end: float
    handle: GotoHandle


class GotoRunner:
    """Runs gotos at ``rate_hz`` (the write rate of the sync loops)."""

    def __init__(
        self,
        rate_hz: float = DEFAULT_RATE_HZ,
        *,
        name: str = "goto",
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.period_s = 1.0 / rate_hz
        self.name = name
        self._clock = clock
        self._lock = threading.Lock()
        self._moves: dict[int, _Move] = {}
        self._thread: Worker | None = None  # one per run: it ends when no goto is left
        self._closed = False

    @property
    def active(self) -> int:
        """Number of motors moving under a goto."""
        with self._lock:
            return len(self._moves)

    def start(
        self, targets: Mapping[_Target, float], duration_s: float, control: str | None
    ) -> GotoHandle:
        """Start moving each motor to its target (degrees, user frame) in ``duration_s``.

        ``control`` None: each motor's ``goto_behavior``; ``"minijerk"`` is ``"minjerk"``.

        Raises:
            ArgumentError: unknown ``control``, a negative or not finite duration.
            RobotClosedError: the runner (its robot) is closed.
        """
        check_goto(duration_s, control or "minjerk")
        controls = {
            motor: control_name(control if control is not None else motor.goto_behavior)
            for motor in targets
        }
        handle = GotoHandle(len(targets), duration_s)
        now = self._clock()
        with self._lock:
            if self._closed:
                raise RobotClosedError("the robot is closed: no more motions")
            for motor, target in targets.items():
                self._cancel_locked(motor)
                plan = plan_goto(
                    motor.present_position,
                    float(target),
                    duration_s,
                    controls[motor],
                    None if motor.wheel_mode else motor.angle_limit,
                    min_speed=abs(float(motor.model.register("moving_speed").to_si(1))),
                )
                motor.moving_speed = plan.speed
                if plan.trajectory is None:
                    link_of(motor).set_goal(plan.goal)
                self._moves[id(motor)] = _Move(
                    motor, plan.goal, plan.trajectory, now, now + duration_s, handle
                )
            if self._moves and self._thread is None:
                self._thread = Worker.periodic(
                    self.name, 1.0 / self.period_s, self._step, clock=self._clock
                )
                self._thread.start()
        return handle

    def goals(self) -> dict[str, float]:
        """Each motor moving under a goto -> the goal it goes to (degrees, user frame)."""
        with self._lock:
            return {move.motor.name: move.goal for move in self._moves.values()}

    def cancel(self, motor: GotoTarget) -> None:
        """Stop the goto of ``motor`` where it is (its goal stays the last one sent)."""
        with self._lock:
            self._cancel_locked(motor)

    def _cancel_locked(self, motor: GotoTarget) -> None:
        move = self._moves.pop(id(motor), None)
        if move is not None:
            move.handle._finish_one(cancelled=True)

    def close(self) -> None:
        """Cancel every goto and join the thread (idempotent)."""
        with self._lock:
            self._closed = True
            for move in self._moves.values():
                move.handle._finish_one(cancelled=True)
            self._moves.clear()
            thread = self._thread
        if thread is not None:
            thread.close(2.0)

    def _step(self, now: float) -> bool:
        """Advance every move; False when none is left (the thread then ends)."""
        with self._lock:
            for key, move in list(self._moves.items()):
                try:
                    if move.trajectory is not None:
                        link_of(move.motor).set_goal(move.trajectory.position(now - move.t0))
                except Exception:
                    logger.exception("goto of %s failed; stopping it", move.motor.name)
                    del self._moves[key]
                    move.handle._finish_one(cancelled=True)
                    continue
                if now >= move.end:
                    if move.trajectory is not None:
                        link_of(move.motor).set_goal(move.goal)
                    del self._moves[key]
                    move.handle._finish_one(cancelled=False)
            if not self._moves or self._closed:
                self._thread = None
                return False
            return True


def running_goals(motors: Iterable[GotoTarget]) -> dict[str, float]:
    """Each of ``motors`` moving under a goto -> the goal it goes to (the page's 3D ghost)."""
    names = {motor.name for motor in motors}
    runners = {id(link_of(m).runner): link_of(m).runner for m in motors}
    goals: dict[str, float] = {}
    for runner in runners.values():
        goals.update((name, goal) for name, goal in runner.goals().items() if name in names)
    return goals
