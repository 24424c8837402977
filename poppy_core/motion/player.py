"""``MovePlayer``: plays a ``Move`` on a robot, interpolating frames at the robot's write rate.

Each loop starts with a gentle minimum-jerk ramp from where the motors are to the move's first
frame, then streams goal positions interpolated between frames, ``speed`` times faster than
recorded, until the last frame.
"""

from __future__ import annotations

import logging
import os
import threading
import time
from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

from poppy_core import checks
from poppy_core.errors import ArgumentError, ConfigError
from poppy_core.motion.move import Move
from poppy_core.motion.move_format import read_move
from poppy_core.motion.play_plan import (
    DEFAULT_RAMP_SPEED_DPS,
    MAX_LOOPS,
    MAX_SPEED,
    MIN_SPEED,
    Phase,
    PlayProgress,
    ProgressCallback,
    clamp_to_limits,
    missing_motors,
    played_fraction,
    ramp_timing,
    within_limits,
    write_rate_hz,
)
from poppy_core.schedule import Gate, Ticker, Worker

if TYPE_CHECKING:
    from poppy_core.robot import Motor, Robot

logger = logging.getLogger(__name__)


class MovePlayer:
    """Plays a move on a robot (stiffening its motors).

    Args:
        robot: the robot.
        move: the move; every motor it names must be on the robot.
        speed: play speed factor (2.0 = twice as fast, half the time).
        backwards: play from the last frame to the first.
        loops: how many times to play it.
        ramp_s: duration of the ramp to the first frame; None picks the largest distance over
            ``ramp_speed_dps`` (at least ``MIN_RAMP_S``; none when already there).
        ramp_speed_dps: mean speed of the automatic ramp.
        play_speed: pypot's name for ``speed`` (negative: backwards).
        move_filename: pypot's: a move file to play instead of ``move``.
        start_max_speed: pypot's name for ``ramp_speed_dps``.
        rate_hz: goal update rate; None uses the robot's write rate.
        on_progress: called at each update with a ``PlayProgress``.
        clock: the time source (seconds).

    Positions past a motor's angle limits are played at the limit (``clamped`` says by how
    much, and a warning is logged), so the ramp to the first frame is planned on reachable
    positions.

    Raises:
        ConfigError: the robot lacks motors of the move (they are named).
        ArgumentError: an empty move, a speed or loop count out of range.
    """

    def __init__(
        self,
        robot: Robot,
        move: Move | None = None,
        speed: float = 1.0,
        backwards: bool = False,
        loops: int = 1,
        *,
        ramp_s: float | None = None,
        ramp_speed_dps: float = DEFAULT_RAMP_SPEED_DPS,
        rate_hz: float | None = None,
        on_progress: ProgressCallback | None = None,
        clock: Callable[[], float] = time.monotonic,
        play_speed: float | None = None,
        move_filename: str | os.PathLike[str] | None = None,
        start_max_speed: float | None = None,
    ) -> None:
        if play_speed is not None:  # pypot's name; a negative speed plays backwards, as pypot
            speed, backwards = abs(play_speed) or 1.0, backwards != (play_speed < 0)
        if start_max_speed is not None:
            ramp_speed_dps = start_max_speed
        if move is None:
            if move_filename is None:
                raise ArgumentError("give the move, or move_filename= a move file", field="move")
            move = read_move(move_filename)
        checks.in_range(speed, MIN_SPEED, MAX_SPEED, "speed")
        if not 1 <= loops <= MAX_LOOPS:
            raise ArgumentError(
                f"loops must be 1-{MAX_LOOPS}, got {loops}", field="loops", value=loops
            )
        if len(move) == 0:
            raise ArgumentError("the move has no frame to play", field="move", value=move)
        missing = missing_motors(robot, move)
        if missing:
            known = ", ".join(m.name for m in robot.motors)
            raise ConfigError(
                f"the robot lacks the move's motor{'s' if len(missing) > 1 else ''} "
                f"{', '.join(missing)} (robot motors: {known})",
                field="motors",
                value=missing,
                reason="missing motors",
            )
        self.robot = robot
        self.move = move
        self.speed = float(speed)
        self.backwards = backwards
        self.loops = int(loops)
        self.ramp_s = None if ramp_s is None else checks.duration(ramp_s, "ramp_s")
        self.ramp_speed_dps = ramp_speed_dps
        self.rate_hz = rate_hz if rate_hz is not None else write_rate_hz(robot)
        self.on_progress = on_progress
        self._clock = clock
        self._motors: list[Motor] = [robot.motor(name) for name in move.motors]
        self.clamped = clamp_to_limits(move, self._motors)
        """Motor -> how far (degrees) the move went past its angle limits, for each motor it did
        (those frames are played at the limit)."""
        if self.clamped:
            logger.warning(
                "the move goes past the angle limits of %s: played at the limits",
                ", ".join(f"{n} (by {d:.1f}°)" for n, d in self.clamped.items()),
            )
        played = within_limits(move, self._motors) if self.clamped else move
        self._played = played.reversed() if backwards else played
        self._worker: Worker | None = None
        self._gate: Gate | None = None
        self.loop_times: list[tuple[float, float]] = []
        """``(start, end)`` clock times of each loop's playing phase (ramps excluded)."""
        self.stopped = False

    @property
    def error(self) -> BaseException | None:
        """What ended the last playback early (logged once), None when it ended well."""
        return self._worker.error if self._worker is not None else None

    @property
    def played(self) -> Move:
        """The move as it is played: reversed when backwards, positions within the limits."""
        return self._played

    @property
    def duration_s(self) -> float:
        """Time the playback takes, ramps excluded."""
        return self.move.duration_s * self.loops / self.speed

    @property
    def played_s(self) -> float:
        """Time spent playing so far (ramps excluded)."""
        return sum(end - start for start, end in self.loop_times)

    # -- control -----------------------------------------------------------------------------

    def start(self, *, gate: Gate | None = None) -> MovePlayer:
        """Start playing in a thread.

        With a ``gate``, the start is armed: the thread is made now and plays once the gate
        opens; a ``stop()`` before that cancels the gate and nothing is played.

        A gate with a start time (``Gate.at``, a fleet's shared start) is the first loop's time
        origin, so that robots started together play in phase whenever their thread wakes (a
        late one plays the frame due now, not frame 0), when the ramp allows it:

        - the robot is already at the first frame (within ``RAMP_SKIP_DEG``): no ramp, frame
          ``k`` is played at ``at + k / (framerate * speed)``;
        - ``ramp_s`` is given: the ramp ends at ``at + ramp_s`` (a late thread's ramp is that
          much shorter) and the frames count from there;
        - otherwise the robot needs a ramp whose length depends on how far it is: it ramps,
          then plays from frame 0 as an un-gated start does, out of phase with the others
          (logged at INFO; give ``ramp_s`` to keep it in phase).

        The next loops and an un-gated start count from when their ramp ends.

        Raises:
            RuntimeError: already playing.
        """
        if self.playing:
            raise RuntimeError("the move is already playing")
        self.loop_times = []
        self.stopped = False
        # One worker per playback: a thread that ended may still be finishing when the next
        # playback starts.
        self._gate = gate
        body = self._run if gate is None else lambda stopping: self._run_at(gate, stopping)
        self._worker = Worker("move player", body)
        self._worker.start()
        return self

    def play(self) -> MovePlayer:
        """Play the whole move; returns when it is over (or ``stop()`` from another thread)."""
        self.start()
        self.wait()
        if self.error is not None:
            raise self.error
        return self

    def wait(self, timeout_s: float | None = None) -> bool:
        """Block until the playback ends; False when ``timeout_s`` ran out first."""
        worker = self._worker
        return worker.wait(timeout_s) if worker is not None else True

    def stop(self) -> None:
        """Stop where the motors are (they stay stiff); joins the thread (but from itself)."""
        if self._gate is not None:
            self._gate.cancel()  # an armed start that has not fired never will
        worker = self._worker
        if worker is not None:
            worker.close(5.0)

    @property
    def playing(self) -> bool:
        """True while the thread runs."""
        return self._worker is not None and self._worker.running

    # -- pypot's names (its MovePlayer is a primitive) -------------------------------------------

    def wait_to_stop(self, timeout_s: float | None = None) -> bool:
        """``wait``: block until the playback ends."""
        return self.wait(timeout_s)

    def is_alive(self) -> bool:
        """``playing``."""
        return self.playing

    def duration(self) -> float:
        """``duration_s``: the time the playback takes, ramps excluded."""
        return self.duration_s

    # -- thread ------------------------------------------------------------------------------

    def _report(self, phase: Phase, loop: int, move_t_s: float, fraction: float) -> None:
        if self.on_progress is None:
            return
        try:
            self.on_progress(PlayProgress(phase, loop, self.loops, move_t_s, fraction))
        except Exception:
            logger.exception("progress callback failed")

    def _set_goals(self, positions: np.ndarray[tuple[int], np.dtype[np.float64]]) -> None:
        for motor, value in zip(self._motors, positions.tolist(), strict=True):
            motor.goal_position = value

    def _on_clock(self, at: float) -> float:
        """``at`` (a ``time.monotonic()`` time) on the player's clock."""
        if self._clock is time.monotonic:
            return at
        return self._clock() - (time.monotonic() - at)

    def _ramp(self, loop: int, stopping: threading.Event, shared: float | None) -> float | None:
        """Go to the first frame; returns when (player's clock) the frames count from, None for
        when the ramp ended. ``shared``: the shared start (player's clock), None when there is
        none."""
        first = self._played.positions[0]
        distance = max(
            abs(m.present_position - float(v)) for m, v in zip(self._motors, first, strict=True)
        )
        duration, origin = ramp_timing(
            distance, self.ramp_s, self.ramp_speed_dps, shared, self._clock
        )
        if shared is not None and origin is None:
            logger.info(
                "%.1f° from the move's first frame: the playback starts after a %.1f s ramp, "
                "not in phase with the shared start (give ramp_s to keep it)",
                distance,
                duration,
            )
        shared = origin
        if duration <= 0:
            if shared is None:  # else the playback writes the frame due at once
                self._set_goals(first)
            return shared
        targets = {m.name: float(v) for m, v in zip(self._motors, first, strict=True)}
        handle = self.robot.goto_position(targets, duration, control="minjerk")
        while not handle.wait(0.05):
            self._report("ramp", loop, 0.0, (loop - 1) / self.loops)
            if stopping.is_set():
                for motor in self._motors:
                    motor.goal_position = motor.present_position
                return None
        return shared

    def _play_once(self, loop: int, stopping: threading.Event, origin: float | None) -> None:
        """Play the frames, counted from ``origin`` (player's clock; None: from now)."""
        move = self._played
        start = self._clock() if origin is None else origin  # a gate's: the first frame's time
        duration = move.duration_s

        def frame(now: float) -> bool:
            move_t = (now - start) * self.speed
            if move_t >= duration:
                self._set_goals(move.positions[-1])
                return False
            self._set_goals(move.positions_at(move_t))
            shown_t = duration - move_t if self.backwards else move_t
            self._report("play", loop, shown_t, played_fraction(loop, self.loops, move_t, duration))
            return True

        # a frame that raises ends the play (``error``; ``play()`` raises it): nothing retried
        ticker = Ticker("move player", self.rate_hz, frame, clock=self._clock, retry=())
        try:
            ticker.run(stopping, start)
        finally:
            self.loop_times.append((start, self._clock()))

    def _run_at(self, gate: Gate, stopping: threading.Event) -> None:
        """``_run`` once ``gate`` opens (nothing when it was cancelled)."""
        if gate.wait() and not stopping.is_set():
            self._run(stopping, gate.at)
        else:
            self.stopped = True

    def _run(self, stopping: threading.Event, at: float | None = None) -> None:
        """The playback (an exception is the worker's: logged once, kept in ``error``); ``at``:
        the shared start (``time.monotonic()``) the first loop counts from, if any."""
        shared = None if at is None else self._on_clock(at)
        for motor in self._motors:
            motor.compliant = False
        for loop in range(1, self.loops + 1):
            if stopping.is_set():
                break
            origin = self._ramp(loop, stopping, shared if loop == 1 else None)
            if stopping.is_set():
                break
            self._play_once(loop, stopping, origin)
        self.stopped = stopping.is_set()
        fraction = 1.0
        if self.stopped and self.duration_s > 0:
            fraction = min(1.0, self.played_s / self.duration_s)
        end_t = 0.0 if self.backwards else self.move.duration_s
        self._report("done", self.loops, end_t, fraction)

    # -- context manager -----------------------------------------------------------------------

    def __enter__(self) -> MovePlayer:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()
