"""What a move playback plays and when: its limits, write rate, ramp length and progress."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal

import numpy as np

from poppy_core.motion.move import Move

if TYPE_CHECKING:
    from poppy_core.robot import Motor, Robot

DEFAULT_RATE_HZ = 50.0
DEFAULT_RAMP_SPEED_DPS = 60.0
"""Mean speed of the ramp to the first frame (a minimum-jerk peak is 1.875 times that)."""
MIN_RAMP_S = 0.3
MIN_SPEED = 0.01
MAX_SPEED = 100.0
MAX_LOOPS = 10_000
LIMIT_TOLERANCE_DEG = 0.5
"""Past a limit by less than this is noise of a recording at the limit: clamped silently."""
RAMP_SKIP_DEG = 0.5
"""No ramp when every motor is already this close to the first frame."""

Phase = Literal["ramp", "play", "done"]


@dataclass(frozen=True)
class PlayProgress:
    """Where a playback is, given to the progress callback.

    Attributes:
        phase: ``"ramp"`` (going to the first frame), ``"play"`` or ``"done"``.
        loop: the loop being played, from 1.
        loops: how many loops in all.
        move_t_s: time in the move (0..``Move.duration_s``; counts down when backwards).
        fraction: share of the whole playback done (ramps excluded), 0..1.
    """

    phase: Phase
    loop: int
    loops: int
    move_t_s: float
    fraction: float


ProgressCallback = Callable[[PlayProgress], None]


def write_rate_hz(robot: Robot) -> float:
    """The rate the robot writes goals at (its slowest ``goals`` loop; 50 Hz if unknown)."""
    rates = [
        loop.target_hz
        for stats in robot.sync_stats().values()
        for name, loop in stats.loops.items()
        if name == "goals" and loop.target_hz > 0
    ]
    return min(rates) if rates else DEFAULT_RATE_HZ


def clamp_to_limits(move: Move, motors: list[Motor]) -> dict[str, float]:
    """How far past its angle limits each motor of ``move`` goes (motors within are left out).

    Args:
        move: the move.
        motors: the robot's motors, one per column of the move (wheels have no limits).
    """
    beyond: dict[str, float] = {}
    for index, motor in enumerate(motors):
        if motor.wheel_mode or not len(move):
            continue
        low, high = motor.angle_limit
        column = move.positions[:, index]
        worst = max(low - float(column.min()), float(column.max()) - high, 0.0)
        if worst > LIMIT_TOLERANCE_DEG:
            beyond[motor.name] = worst
    return beyond


def within_limits(move: Move, motors: list[Motor]) -> Move:
    """``move`` with each motor's positions clipped to its angle limits (wheels left alone)."""
    positions = move.positions.copy()
    for index, motor in enumerate(motors):
        if not motor.wheel_mode:
            low, high = motor.angle_limit
            np.clip(positions[:, index], low, high, out=positions[:, index])
    return Move(move.framerate, move.motors, positions, speeds=move.speeds, metadata=move.metadata)


def missing_motors(robot: Robot, move: Move) -> list[str]:
    """The motors of ``move`` the robot does not have."""
    names = {m.name for m in robot.motors}
    return [m for m in move.motors if m not in names]


def ramp_timing(
    distance: float,
    ramp_s: float | None,
    ramp_speed_dps: float,
    shared: float | None,
    clock: Callable[[], float],
) -> tuple[float, float | None]:
    """How long the ramp to the first frame lasts, and when the frames count from.

    Args:
        distance: the largest distance (degrees) of a motor from the first frame.
        ramp_s: the ramp's given length; None picks ``distance`` over ``ramp_speed_dps`` (at
            least ``MIN_RAMP_S``; none within ``RAMP_SKIP_DEG``).
        ramp_speed_dps: mean speed of the automatic ramp.
        shared: the shared start (on ``clock``), None when there is none.
        clock: the player's clock, read only for a given ramp with a shared start.

    Returns:
        ``(duration, origin)``: the ramp's length left (0 or less: none), and when (on
        ``clock``) the frames count from (None: when the ramp ends). A ramp of a given length
        ends at ``shared + ramp_s`` on every robot (a late thread's is that much shorter); an
        automatic one, its length the robot's own, drops the shared start (origin None).
    """
    duration = ramp_s
    if duration is None:
        duration = 0.0 if distance < RAMP_SKIP_DEG else max(MIN_RAMP_S, distance / ramp_speed_dps)
        if duration > 0:
            shared = None  # a ramp of the robot's own length: out of phase with the others
    elif shared is not None:
        shared += duration  # a ramp of a given length ends at the same time on every robot
        duration = shared - clock()  # the rest of it, for a thread that woke late
    return duration, shared


def played_fraction(loop: int, loops: int, move_t_s: float, duration_s: float) -> float:
    """Share of a playback of ``loops`` loops done at ``move_t_s`` into loop ``loop`` (from 1)."""
    return (loop - 1 + move_t_s / duration_s) / loops if duration_s else 0.0
