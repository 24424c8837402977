"""A shared start is the motion's time origin: a gate's ``at`` is where a gated primitive's
elapsed time, a LoopPrimitive's update grid and a MovePlayer's frames count from.

A robot whose thread wakes late (a loaded machine) catches up with what is due instead of
playing from the beginning, late: robots started together stay in phase. The gates here are
opened late on purpose; the checks are on values and order, not on timing.
"""

from __future__ import annotations

import math
import threading
import time
from typing import ClassVar

import numpy as np
import pytest

from poppy_core.motion import PositionWatcher, Sinus
from poppy_core.motion.move import Move
from poppy_core.motion.play_plan import RAMP_SKIP_DEG, PlayProgress
from poppy_core.motion.player import MovePlayer
from poppy_core.robot import Robot
from poppy_core.schedule import Gate, Periodic, pacing
from tests.helpers import eventually
from tests.helpers.fixtures import ergo_fixture

ergo = ergo_fixture(home=True, creature=False)

LATE_S = 0.3


def open_late(gate: Gate, late_s: float) -> None:
    """Open ``gate`` once ``late_s`` past its ``at`` (never before)."""
    assert gate.at is not None
    while (left := gate.at + late_s - time.monotonic()) > 0:
        time.sleep(left)
    gate.open()


class Traced(Sinus):
    """A Sinus noting each (elapsed time, value) it computes, and when its time counts from."""

    def __init__(self, robot: Robot) -> None:
        super().__init__(robot, 20.0, "m1", amp=10.0, freq=0.2)
        self.trace: list[tuple[float, float]] = []
        self.origins: list[float] = []

    def signal(self, t_s: float) -> float:
        self.origins.append(time.monotonic() - t_s)  # never before the true origin
        value = super().signal(t_s)
        self.trace.append((t_s, value))
        return value


def test_a_late_gated_sinus_starts_with_the_value_due_at_the_shared_start(ergo: Robot) -> None:
    sinus = Traced(ergo)
    gate = Gate(at=time.monotonic())
    sinus.start(gate=gate)
    open_late(gate, LATE_S)
    assert eventually(lambda: len(sinus.trace) >= 2)
    sinus.stop()
    t_s, value = sinus.trace[0]
    assert t_s >= LATE_S  # counted from the shared start, not from the wake-up
    assert value == 10.0 * math.sin(2 * math.pi * 0.2 * t_s)
    assert value > 10.0 * math.sin(2 * math.pi * 0.2 * 0.9 * LATE_S)  # not the value at 0
    assert gate.at is not None and sinus.origins[0] >= gate.at
    assert sinus.shared_start == gate.at
    assert sinus.elapsed_time >= sinus.trace[-1][0]


def test_an_ungated_primitive_counts_from_its_own_start(ergo: Robot) -> None:
    sinus = Traced(ergo)
    started = time.monotonic()
    sinus.start()
    assert eventually(lambda: len(sinus.trace) >= 1)
    sinus.stop()
    assert sinus.shared_start is None and sinus.origins[0] >= started
    gated = Traced(ergo)
    gate = Gate()  # no start time: the wake-up is the origin, as before
    gated.start(gate=gate)
    time.sleep(LATE_S)  # armed a while
    opened = time.monotonic()
    gate.open()
    assert eventually(lambda: len(gated.trace) >= 1)
    gated.stop()
    assert gated.shared_start is None and gated.origins[0] >= opened


class Stamped(PositionWatcher):
    """A watcher noting when (monotonic) its thread woke and each update ran."""

    def __init__(self, robot: Robot, freq: float = 10.0) -> None:
        super().__init__(robot, freq, "m1")
        self.woke: list[float] = []
        self.thread = 0
        self.updated: list[float] = []

    def setup(self) -> None:
        self.thread = threading.get_ident()
        self.woke.append(time.monotonic())
        super().setup()

    def update(self) -> None:
        self.updated.append(time.monotonic())
        super().update()


def _phase(t_s: float, period_s: float) -> float:
    """How far ``t_s`` is from the nearest multiple of ``period_s``, in periods (0..0.5)."""
    cycles = (t_s / period_s) % 1.0
    return min(cycles, 1.0 - cycles)


class Deadlines(Periodic):
    """The loop primitives' schedule, noting every deadline it sets (``made``: all of them)."""

    made: ClassVar[list[Deadlines]] = []

    def __init__(self, period_s: float, start_s: float, catch_up: int = 0) -> None:
        super().__init__(period_s, start_s, catch_up)
        self.deadlines = [start_s]
        self.thread = threading.get_ident()
        Deadlines.made.append(self)

    def advance(self, now_s: float) -> int:
        skipped = super().advance(now_s)
        self.deadlines.append(self.next_deadline)
        return skipped


def test_gated_loop_primitives_opened_apart_update_on_one_grid(
    ergo: Robot, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(pacing, "Periodic", Deadlines)  # the deadlines of every Ticker
    monkeypatch.setattr(Deadlines, "made", [])
    freq = 4.0
    period = 1.0 / freq
    at = time.monotonic()
    watchers = [Stamped(ergo, freq) for _ in range(2)]
    gates = [Gate(at=at), Gate(at=at)]
    for watcher, gate in zip(watchers, gates, strict=True):
        watcher.start(gate=gate)
    gates[0].open()
    open_late(gates[1], 1.5 * period)  # half a period off the first one's grid
    assert eventually(lambda: all(len(w.updated) >= 6 for w in watchers))
    for watcher in watchers:
        watcher.stop()
    threads = {w.thread for w in watchers}
    mine = [schedule for schedule in Deadlines.made if schedule.thread in threads]
    schedules = {schedule.thread: schedule for schedule in mine}
    assert len(mine) == 2 and threads == set(schedules)
    for watcher in watchers:
        # every update is due on the one grid at + k * period and runs at or after its deadline
        # (how late, on a loaded machine: `python -m bench timing`)
        deadlines = schedules[watcher.thread].deadlines
        assert all(_phase(d - at, period) < 1e-6 for d in deadlines), [d - at for d in deadlines]
        assert all(t >= d - 0.001 for t, d in zip(watcher.updated, deadlines, strict=False))
        # and its elapsed time is the time since the shared start
        assert all(e >= t - at for e, t in zip(watcher.times, watcher.updated, strict=True))
    assert watchers[1].times[0] >= 1.5 * period  # its first update: the value due then


def test_a_gate_opened_before_its_start_time_holds_the_first_update(ergo: Robot) -> None:
    watcher = Stamped(ergo)
    at = time.monotonic() + LATE_S
    gate = Gate(at=at)
    watcher.start(gate=gate)
    gate.open()  # early
    assert eventually(lambda: len(watcher.updated) >= 2)
    watcher.stop()
    assert watcher.woke[0] < at  # it woke early, and did its first update at its start time
    assert watcher.updated[0] >= at


def wave(frames: int = 41, rate: float = 10.0, base: float = 0.0) -> Move:
    """m1 climbs one degree a frame from ``base``."""
    return Move.from_frames(rate, [{"m1": base + i} for i in range(frames)])


class Noted(MovePlayer):
    """A player noting each goal of m1 it writes, and its progress."""

    def __init__(self, robot: Robot, move: Move, ramp_s: float | None = None) -> None:
        self.progress: list[PlayProgress] = []
        super().__init__(robot, move, ramp_s=ramp_s, on_progress=self.progress.append)
        self.goals: list[float] = []

    def playing_phase(self) -> bool:
        return any(p.phase == "play" for p in self.progress)

    def _set_goals(self, positions: np.ndarray[tuple[int], np.dtype[np.float64]]) -> None:
        self.goals.append(float(positions[0]))
        super()._set_goals(positions)


def test_a_late_gated_move_plays_the_frame_due_not_frame_0(ergo: Robot) -> None:
    assert abs(ergo.motor("m1").present_position) < RAMP_SKIP_DEG  # at the first frame: no ramp
    player = Noted(ergo, wave())
    gate = Gate(at=time.monotonic())
    player.start(gate=gate)
    open_late(gate, LATE_S)
    assert eventually(lambda: len(player.goals) >= 2)
    player.stop()
    assert player.goals[0] >= 10.0 * LATE_S - 1e-6  # the frame due 0.3 s in, at 10 frames/s
    first_play = next(p for p in player.progress if p.phase == "play")
    assert first_play.move_t_s >= LATE_S
    assert player.loop_times[0][0] == gate.at  # the playback counted from the shared start


def test_a_given_ramp_ends_at_the_same_time_on_every_robot(ergo: Robot) -> None:
    player = Noted(ergo, wave(base=20.0), ramp_s=0.6)  # 20° away: a ramp comes first
    gate = Gate(at=time.monotonic())
    player.start(gate=gate)
    open_late(gate, LATE_S)
    assert eventually(player.playing_phase)
    player.stop()
    assert gate.at is not None
    assert player.loop_times[0][0] == gate.at + 0.6  # frames count from the shared ramp's end


def test_an_automatic_ramp_plays_from_frame_0_after_it(ergo: Robot) -> None:
    player = Noted(ergo, wave(base=20.0))  # 20° away, no ramp_s: a ramp of its own length
    gate = Gate(at=time.monotonic())
    player.start(gate=gate)
    open_late(gate, LATE_S)
    assert eventually(player.playing_phase)
    player.stop()
    assert gate.at is not None
    assert player.loop_times[0][0] > gate.at + LATE_S  # after its ramp, not at the shared start
    first_play = next(p for p in player.progress if p.phase == "play")
    assert first_play.move_t_s < LATE_S  # from the start of the move, not the frame due
