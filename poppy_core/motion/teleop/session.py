"""``teleoperate(leader, follower)``: a follower robot copies a leader moved by hand.

Each tick (``rate_hz``, drift-free) reads the leader's present positions (the leader's
``present`` loop is driven by the teleoperation, so the read happens right before it is used),
maps them to the follower's joints (``JointMap``; user frames, so two calibrated robots agree),
and hands the targets to the follower, which writes them at once. The follower starts with a
ramp from where it is, holds where it is when the leader is lost (a bus error, a silent motor)
and ramps again when it comes back. Stopping holds the follower where it is, stiff (as ``poppy
play``); the leader stays compliant.

The follower is a local ``Robot`` (hardware or simulated) or anything with the ``Follower``
interface, such as ``poppy_core.remote.RemoteFollower`` (a robot served by ``poppy serve``,
driven over its WebSocket).
"""

from __future__ import annotations

import logging
import threading
import time
from collections import deque
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from poppy_core import checks
from poppy_core.errors import ConfigError, FileError, PoppyError
from poppy_core.motion.teleop.follower import Follower, LocalFollower
from poppy_core.motion.teleop.goal_stream import GoalStreamChange
from poppy_core.motion.teleop.joint_map import JointMap
from poppy_core.motion.teleop.leader import Leader, LeaderMotor
from poppy_core.motion.teleop.recording import TrajectoryRecorder
from poppy_core.motion.teleop.stats import TeleopReport, TeleopStatus
from poppy_core.robot.robot import Robot
from poppy_core.schedule import Ticker, Worker

if TYPE_CHECKING:
    pass

logger = logging.getLogger(__name__)

DEFAULT_RATE_HZ = 100.0
MAX_RATE_HZ = checks.MAX_RATE_HZ
RETRY_FIRST_S = 0.1
RETRY_MAX_S = 1.0
"""A lost leader is read again after 0.1 s, then twice as late each time, up to 1 s."""
KEPT_SAMPLES = 60_000
"""Timing samples kept for the percentiles (10 minutes at 100 Hz)."""

ChangeCallback = Callable[[str, str], None]
"""Called with ``(state, reason)`` when the teleoperation's state changes."""

__all__ = [
    "Follower",
    "LocalFollower",
    "TeleopReport",
    "TeleopStatus",
    "Teleoperation",
    "teleoperate",
]


class _LeaderLost(PoppyError):
    """The leader could not be read (the message says why): the follower holds, the loop
    retries with backoff."""


class Teleoperation:
    """A leader → follower teleoperation run in a thread (``teleoperate`` builds and starts one).

    Args:
        leader: the robot moved by hand (its mapped motors turn compliant).
        follower: a ``Robot`` (wrapped in a ``LocalFollower``) or a ``Follower``.
        joint_map: follower joint ← leader joint; None maps the motors of the same name.
        rate_hz: ticks per second (leader read, targets sent).
        ramp_s: duration of the start and resume ramps (None: from the distance, ≥ 0.3 s).
        duration_s: stop after this long (None: until ``stop``).
        record: save the follower's trajectory as a move there (checkpointed every second).
        record_metadata: header fields of the recorded move.
        on_change: called with ``(state, reason)`` when the state changes.
        clock: monotonic time in seconds.

    Raises:
        ConfigError: a map naming unknown motors, or a leader joint also driven as a follower
            joint of the same robot.
        ArgumentError: a rate that is not ``checks.rate`` (once a day to 1000 Hz).
    """

    def __init__(
        self,
        leader: Leader,
        follower: Robot | Follower,
        joint_map: JointMap | None = None,
        *,
        rate_hz: float = DEFAULT_RATE_HZ,
        ramp_s: float | None = None,
        duration_s: float | None = None,
        record: str | Path | None = None,
        record_metadata: Mapping[str, Any] | None = None,
        on_change: ChangeCallback | None = None,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        checks.rate(rate_hz, "rate_hz")
        self._on_change = on_change
        self._clock = clock
        self.follower: Follower = (
            LocalFollower(follower, ramp_s=ramp_s, on_change=self._follow_changed, clock=clock)
            if isinstance(follower, Robot)
            else follower
        )
        remote: Any = self.follower
        if getattr(remote, "on_change", False) is None:  # a RemoteFollower: report its changes
            remote.on_change = self._changed
        leader_names = [m.name for m in leader.motors]
        self.joint_map = joint_map or JointMap.same_names(leader_names, self.follower.motor_names)
        self.joint_map.check(leader_names, self.follower.motor_names)
        if follower is leader:
            both = sorted(set(self.joint_map.leaders) & set(self.joint_map.followers))
            if both:
                raise ConfigError(
                    f"{', '.join(both)} cannot lead and follow at once (one robot copying itself "
                    "needs distinct leader and follower joints)",
                    field="map",
                    value=both,
                )
        self.leader = leader
        self._leader_motors: list[LeaderMotor] = [leader.motor(n) for n in self.joint_map.leaders]
        self.rate_hz = float(rate_hz)
        self.duration_s = duration_s
        self.recorder = (
            TrajectoryRecorder(
                record, self.joint_map.followers, self.rate_hz, metadata=record_metadata
            )
            if record is not None
            else None
        )
        self._worker: Worker | None = None
        self._ticker = Ticker(
            "teleop",
            self.rate_hz,
            self._tick,
            first_s=RETRY_FIRST_S,
            max_s=RETRY_MAX_S,
            clock=clock,
            retry=(_LeaderLost,),
            on_failure=lambda exc: self._leader_lost(str(exc)),
        )
        self._lock = threading.Lock()
        self._save_error: FileError | None = None
        self._t0 = 0.0
        self._first_tick: float | None = None
        self._last_tick = 0.0
        self._ticks = 0
        self._holds = 0
        self._read_s: deque[float] = deque(maxlen=KEPT_SAMPLES)
        self._pipeline_s: deque[float] = deque(maxlen=KEPT_SAMPLES)
        self._leader_positions: dict[str, float] = {}
        self._targets: dict[str, float] = {}
        self._follower_positions: dict[str, float] = {}
        self._lost: str | None = None
        self._reason = "starting"
        self._finished_at: float | None = None

    # -- control -----------------------------------------------------------------------------

    def start(self) -> Teleoperation:
        """Start in a thread: the leader turns compliant, the follower stiff where it is.

        Raises:
            RuntimeError: already running.
        """
        if self.running:
            raise RuntimeError("the teleoperation is already running")
        self._save_error = None
        # A PoppyError (a follower that failed) is the caller's to say: run() raises it.
        self._worker = Worker("teleop", self._run, on_exit=self._finish, quiet=(PoppyError,))
        self._worker.start()
        return self

    def stop(self) -> None:
        """Stop: the follower holds where it is (stiff); the recorded move is saved. Joins the
        thread (but from itself); stopping twice is safe."""
        worker = self._worker
        if worker is not None:
            worker.close(5.0)

    def wait(self, timeout_s: float | None = None) -> bool:
        """Block until the teleoperation ends (``duration_s`` or ``stop``); False on timeout."""
        worker = self._worker
        return worker.wait(timeout_s) if worker is not None else True

    @property
    def error(self) -> BaseException | None:
        """What stopped the run early (logged once unless a ``PoppyError``), or the record
        that could not be saved; None when it ended well."""
        worker = self._worker
        if worker is not None and worker.error is not None:
            return worker.error
        return self._save_error

    def run(self) -> TeleopReport:
        """Run (or keep running) until ``duration_s`` or ``stop`` from another thread, then
        return the report.

        Raises:
            PoppyError: what stopped it (a follower that failed, a record that cannot be
                written).
        """
        if self._worker is None:
            self.start()
        self.wait()
        if self.error is not None:
            raise self.error
        return self.report()

    @property
    def running(self) -> bool:
        """True while the thread runs."""
        return self._worker is not None and self._worker.running

    # -- reports -------------------------------------------------------------------------------

    def status(self) -> TeleopStatus:
        """What the teleoperation is doing now."""
        with self._lock:
            end = self._finished_at if self._finished_at is not None else self._clock()
            return TeleopStatus(
                state="leader lost" if self._lost else self.follower.state,
                elapsed_s=max(0.0, end - self._t0) if self._t0 else 0.0,
                ticks=self._ticks,
                measured_hz=self._measured_hz(),
                holds=self._holds,
                leader=dict(self._leader_positions),
                targets=dict(self._targets),
                follower=dict(self._follower_positions),
                reason=self._lost or self._reason,
            )

    def report(self) -> TeleopReport:
        """Rate, timings, holds and the record of the run so far."""
        with self._lock:
            end = self._finished_at if self._finished_at is not None else self._clock()
            return TeleopReport(
                rate_hz=self.rate_hz,
                duration_s=max(0.0, end - self._t0) if self._t0 else 0.0,
                ticks=self._ticks,
                measured_hz=self._measured_hz(),
                missed_periods=self._ticker.missed,
                holds=self._holds,
                read_s=list(self._read_s),
                pipeline_s=list(self._pipeline_s),
                record_path=str(self.recorder.path) if self.recorder is not None else None,
                recorded_frames=len(self.recorder.move()) if self.recorder is not None else 0,
            )

    def _measured_hz(self) -> float:
        if self._first_tick is None or self._ticks < 2:
            return 0.0
        span = self._last_tick - self._first_tick
        return (self._ticks - 1) / span if span > 0 else 0.0

    # -- the thread ----------------------------------------------------------------------------

    def _run(self, stopping: threading.Event) -> None:
        """The teleoperation (an exception is the worker's: kept in ``error``, run() raises it;
        ``_finish`` runs after it whatever the way)."""
        with self.leader.driving("present"):
            for motor in self._leader_motors:
                motor.compliant = True
            self._t0 = self._clock()
            self.follower.start(self.joint_map.followers)
            self._ticker.run(stopping, self._t0)

    def _tick(self, now: float) -> bool:
        """One period: the leader read, the follower sent its targets, its positions kept.

        A lost leader raises ``_LeaderLost``: the follower is told to hold, the ticker logs it
        once and retries with backoff (``RETRY_FIRST_S`` doubling to ``RETRY_MAX_S``).
        """
        if self.duration_s is not None and now - self._t0 >= self.duration_s:
            return False
        positions = self._read_leader()
        self._follow(now, positions)
        follower_positions = self.follower.positions()
        if self.recorder is not None:
            self.recorder.sample(now - self._t0, follower_positions)
        with self._lock:
            self._follower_positions = follower_positions
            self._ticks += 1
            self._first_tick = now if self._first_tick is None else self._first_tick
            self._last_tick = now
        return True

    def _read_leader(self) -> dict[str, float]:
        try:
            self.leader.run_loop("present")
        except PoppyError as exc:
            raise _LeaderLost(f"leader read failed: {exc}") from exc
        silent = [m.name for m in self._leader_motors if not m.online]
        if silent:
            raise _LeaderLost(
                f"leader motor{'s' if len(silent) > 1 else ''} {', '.join(silent)} not answering"
            )
        return {m.name: m.present_position for m in self._leader_motors}

    def _follow(self, tick: float, positions: dict[str, float]) -> None:
        read_done = self._clock()
        if self._lost is not None:
            logger.warning("leader back: following again")
            self._lost = None
            self._changed("leader back", "following again after a ramp")
        targets = self.joint_map.apply(positions)
        self.follower.send(targets)
        sent = self._clock()
        with self._lock:
            self._read_s.append(read_done - tick)
            self._pipeline_s.append(sent - read_done)
            self._leader_positions = positions
            self._targets = targets

    def _leader_lost(self, reason: str) -> None:
        if self._lost is None:  # the ticker logs it once
            with self._lock:
                self._lost = reason
                self._holds += 1
            self.follower.hold(reason)
            self._changed("leader lost", reason)

    def _follow_changed(self, change: GoalStreamChange) -> None:
        self._changed(change.state, change.reason)

    def _changed(self, state: str, reason: str) -> None:
        self._reason = reason
        if self._on_change is not None:
            try:
                self._on_change(state, reason)
            except Exception:
                logger.exception("teleoperation state callback failed")

    def _finish(self) -> None:
        try:
            self.follower.stop()
        except PoppyError as exc:
            logger.warning("stopping the follower: %s", exc)
        with self._lock:
            self._finished_at = self._clock()
        if self.recorder is not None:
            try:
                self.recorder.save()
            except (FileError, OSError) as exc:
                if self.error is None:
                    reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else exc
                    self._save_error = FileError(
                        f"cannot save the recorded move to {self.recorder.path}: {reason} "
                        f"({self.recorder.samples} samples kept in memory)",
                        path=str(self.recorder.path),
                    )

    # -- context manager -----------------------------------------------------------------------

    def __enter__(self) -> Teleoperation:
        return self if self.running else self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()


def teleoperate(
    leader: Leader,
    follower: Robot | Follower,
    joint_map: JointMap | str | None = None,
    *,
    rate_hz: float = DEFAULT_RATE_HZ,
    ramp_s: float | None = None,
    duration_s: float | None = None,
    record: str | Path | None = None,
    record_metadata: Mapping[str, Any] | None = None,
    on_change: ChangeCallback | None = None,
) -> Teleoperation:
    """Start a follower copying a leader moved by hand; returns the running ``Teleoperation``.

    ``with teleoperate(leader, follower): ...`` stops at the end of the block;
    ``teleoperate(..., duration_s=10).run()`` waits for the end and returns a ``TeleopReport``.

    Args:
        leader: the robot moved by hand.
        follower: a ``Robot`` or a ``Follower`` (``poppy_core.remote.RemoteFollower``).
        joint_map: a ``JointMap``, its text form (``"r_elbow_y=-m3, ..."``), or None for the
            motors of the same name.
        rate_hz: ticks per second.
        ramp_s: duration of the start and resume ramps (None: from the distance).
        duration_s: stop after this long (None: until ``stop``).
        record: save the follower's trajectory as a move at this path.
        record_metadata: header fields of the recorded move.
        on_change: called with ``(state, reason)`` when the state changes.

    Raises:
        ConfigError: see ``Teleoperation``.
    """
    mapping = JointMap.parse(joint_map) if isinstance(joint_map, str) else joint_map
    teleop = Teleoperation(
        leader,
        follower,
        mapping,
        rate_hz=rate_hz,
        ramp_s=ramp_s,
        duration_s=duration_s,
        record=record,
        record_metadata=record_metadata,
        on_change=on_change,
    )
    return teleop.start()
