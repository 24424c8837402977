"""``GoalStream``: goal positions streamed to some motors, with a start ramp, hold and resume.

The follower side of teleoperation, shared by a local follower (``motion.teleop.follower``) and
the server's WebSocket teleop channel. Targets arrive at the stream's rate; each one is
written at once (``Robot.run_loop("goals")``) rather than at the sync loop's next write.

- **Ramp**: when a stream starts, or resumes after a hold, the goals blend from where the motors
  are to the (moving) target with a minimum-jerk weight, ``goal = start + s(τ) · (target −
  start)``, so the follower never jumps to a leader that is far away.
- **Hold**: ``hold`` sets every goal to the present position (the motors stay stiff where they
  are); the next target starts a new ramp. ``expired`` tells a watchdog that the stream stalled.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal

from poppy_core import checks
from poppy_core.errors import ArgumentError, PoppyError, UnknownMotorError
from poppy_core.trajectory import minimum_jerk_weight

if TYPE_CHECKING:
    from poppy_core.robot import Motor, Robot

logger = logging.getLogger(__name__)

FollowState = Literal["idle", "ramping", "following", "held", "stopped"]
DEFAULT_RAMP_SPEED_DPS = 60.0
"""Mean speed of an automatic ramp (the distance to the target over this, at least
``MIN_RAMP_S``)."""
MIN_RAMP_S = 0.3
RAMP_SKIP_DEG = 0.5
"""No ramp when every motor is already this close to its target."""


@dataclass(frozen=True)
class GoalStreamChange:
    """A change of state, given to ``on_change``: the new state and why."""

    state: FollowState
    reason: str
    time_s: float


class GoalStream:
    """Streams goals to ``motors`` of ``robot`` (see the module docstring).

    Args:
        robot: the follower robot.
        motors: the names of the motors driven.
        ramp_s: duration of each ramp; None picks the largest distance over ``ramp_speed_dps``
            (at least ``MIN_RAMP_S``). No ramp when every motor is already there.
        ramp_speed_dps: mean speed of an automatic ramp.
        watchdog_s: ``expired`` is True once no target arrived for this long (None: never).
        write_now: send the goals to the bus at each target instead of at the next sync write.
        on_change: called with a ``GoalStreamChange`` at each change of state.
        clock: monotonic time in seconds.

    Raises:
        UnknownMotorError: an unknown motor name. ArgumentError: no motor, a bad ramp.
    """

    def __init__(
        self,
        robot: Robot,
        motors: Sequence[str],
        *,
        ramp_s: float | None = None,
        ramp_speed_dps: float = DEFAULT_RAMP_SPEED_DPS,
        watchdog_s: float | None = None,
        write_now: bool = True,
        on_change: Callable[[GoalStreamChange], None] | None = None,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        if not motors:
            raise ArgumentError("no motor to follow", field="motors")
        if ramp_s is not None:
            checks.duration(ramp_s, "ramp_s")
        self.robot = robot
        self.motors: list[Motor] = [robot.motor(name) for name in motors]
        self.ramp_s = ramp_s
        self.ramp_speed_dps = ramp_speed_dps
        self.watchdog_s = watchdog_s
        self.write_now = write_now
        self.on_change = on_change
        self._clock = clock
        self._lock = threading.RLock()
        self.state: FollowState = "idle"
        self._ramp_start: dict[str, float] = {}
        self._ramp_t0 = 0.0
        self._ramp_duration = 0.0
        self._last_target_s: float | None = None
        self.holds = 0
        self.ramps = 0
        self.goals: dict[str, float] = {}
        """The goals written last (user frame)."""

    @property
    def motor_names(self) -> list[str]:
        """The names of the motors driven."""
        return [m.name for m in self.motors]

    # -- control -----------------------------------------------------------------------------

    def start(self) -> None:
        """Stiffen the motors where they are; the first target starts a ramp."""
        with self._lock:
            for motor in self.motors:
                motor.compliant = False
            self._write()
            self._last_target_s = None
            self._set_state("held", "waiting for the first target")

    def push(self, targets: Mapping[str, float]) -> dict[str, float]:
        """Take new targets (user-frame degrees; motors not given keep their goal).

        Returns:
            The goals written (ramped while a ramp runs).

        Raises:
            UnknownMotorError: a motor that is not driven by this session.
        """
        now = self._clock()
        with self._lock:
            if self.state == "stopped":
                return dict(self.goals)
            by_name = {m.name: m for m in self.motors}
            unknown = [name for name in targets if name not in by_name]
            if unknown:
                raise UnknownMotorError(
                    f"not followed: {', '.join(unknown)} (followed: {', '.join(by_name)})",
                    motor=str(unknown[0]),
                    known=list(by_name),
                )
            self._last_target_s = now
            if self.state in ("held", "idle"):
                self._begin_ramp(targets, now)
            weight = 1.0
            if self.state == "ramping":
                elapsed = now - self._ramp_t0
                if elapsed >= self._ramp_duration:
                    self._set_state("following", "ramp done")
                else:
                    weight = minimum_jerk_weight(elapsed / self._ramp_duration)
            for name, target in targets.items():
                motor = by_name[name]
                start = self._ramp_start.get(name, target)
                goal = float(target) if weight >= 1.0 else start + weight * (target - start)
                motor.goal_position = goal
                self.goals[name] = motor.goal_position
            self._write()
            return dict(self.goals)

    def hold(self, reason: str) -> None:
        """Hold every motor where it is (stiff); the next target starts a new ramp."""
        with self._lock:
            if self.state in ("held", "stopped"):
                return
            self._hold_here()
            self.holds += 1
            self._set_state("held", reason)

    def stop(self, reason: str = "stopped") -> None:
        """Hold where the motors are and take no more targets (the motors stay stiff)."""
        with self._lock:
            if self.state == "stopped":
                return
            if self.state in ("ramping", "following"):
                self._hold_here()
            self._set_state("stopped", reason)

    def expired(self, now_s: float | None = None) -> bool:
        """True when the stream runs (ramping or following) and no target came for
        ``watchdog_s``."""
        if self.watchdog_s is None or self.state not in ("ramping", "following"):
            return False
        last = self._last_target_s
        now = self._clock() if now_s is None else now_s
        return last is not None and now - last > self.watchdog_s

    def positions(self) -> dict[str, float]:
        """The present positions of the motors driven (user frame, as last read)."""
        return {m.name: m.present_position for m in self.motors}

    # -- inside --------------------------------------------------------------------------------

    def _begin_ramp(self, targets: Mapping[str, float], now: float) -> None:
        start = {m.name: m.present_position for m in self.motors}
        distance = max((abs(float(v) - start[n]) for n, v in targets.items()), default=0.0)
        duration = self.ramp_s
        if distance < RAMP_SKIP_DEG:
            duration = 0.0
        elif duration is None:
            duration = max(MIN_RAMP_S, distance / self.ramp_speed_dps)
        self._ramp_start = start
        self._ramp_t0 = now
        self._ramp_duration = duration
        if duration > 0:
            self.ramps += 1
            self._set_state("ramping", f"{distance:.1f}° away: ramp of {duration:.2f} s")
        else:
            self._set_state("following", "already there")

    def _hold_here(self) -> None:
        for motor in self.motors:
            motor.goal_position = motor.present_position
            self.goals[motor.name] = motor.goal_position
        self._write()

    def _write(self) -> None:
        if not self.write_now:
            return
        try:
            self.robot.run_loop("goals")
        except PoppyError as exc:  # the sync loop sends them at its next write
            logger.debug("immediate goal write failed: %s", exc)

    def _set_state(self, state: FollowState, reason: str) -> None:
        if state == self.state:
            return
        self.state = state
        logger.info("follower %s: %s", state, reason)
        if self.on_change is not None:
            try:
                self.on_change(GoalStreamChange(state, reason, self._clock()))
            except Exception:
                logger.exception("follow state callback failed")
