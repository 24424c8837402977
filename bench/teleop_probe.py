"""What the teleoperation benchmark sees on the wire: a hand on the leader, probes on the buses.

Everything is measured at the emulators, the same way for every client (poppy local, poppy
remote, pypot), on one clock (``time.perf_counter``):

- ``BusProbe`` wraps a ``VirtualBus``'s ``receive``: for each read of the present position it
  logs when the reply leaves the emulator and the positions it carried; for each instruction that
  changes a watched goal it logs when the bytes arrived and the new goal.
- ``Hand`` moves the leader's virtual servos as a hand moves a compliant arm: smooth strokes
  (the "recorded hand move": seeded minimum-jerk strokes between random postures, 20-70°/s) and
  steps (a jump every ``STEP_S``, to time the pipeline without ambiguity).
- ``latencies``: leader read reply → follower goal write, per step and joint: the first read that
  carried the new position, to the first goal write of the follower's matching value.
- ``Tracker`` samples the leader's hand and the follower's horns at 100 Hz during the strokes.
"""

from __future__ import annotations

import math
import random
import threading
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from poppy_core.emulator import VirtualBus, VirtualMotor
from poppy_core.protocol import Instruction, InstructionPacket, PacketDecoder
from poppy_core.trajectory import MinimumJerk

READS = {
    Instruction.READ,
    Instruction.SYNC_READ,
    Instruction.SYNC_READ_USB2AX,
    Instruction.FAST_SYNC_READ,
    Instruction.BULK_READ,
}
STEP_S = 0.2
SAMPLE_HZ = 100.0

FollowerOf = Mapping[str, tuple[int, Callable[[float], float]]]
"""Leader joint -> (follower servo id, leader motor-frame degrees -> follower goal degrees)."""


def _read_address(protocol: int, packet: InstructionPacket) -> int | None:
    params = packet.params
    if packet.instruction == Instruction.BULK_READ:
        if protocol == 1 and len(params) >= 4:
            return params[3]
        return params[1] | params[2] << 8 if len(params) >= 3 else None
    if protocol == 1:
        return params[0] if params else None
    return params[0] | params[1] << 8 if len(params) >= 2 else None


@dataclass
class BusProbe:
    """Logs present-position reads of ``read_ids`` and goal changes of ``goal_ids``."""

    bus: VirtualBus
    read_ids: Sequence[int]
    goal_ids: Sequence[int]
    reads: list[tuple[float, dict[int, float]]] = field(default_factory=list)
    goals: list[tuple[float, int, float]] = field(default_factory=list)

    def __post_init__(self) -> None:
        self._decoder = PacketDecoder(self.bus.protocol, "instruction")
        self._original = self.bus.receive
        self._motors = {m.id: m for m in self.bus.motors}
        model = self.bus.motors[0].model
        self._present = model.register("present_position").address
        self._lock = self.bus.motors[0].lock  # the bus's lock: the hand waits for it too
        self.bus.receive = self._receive  # type: ignore[method-assign]

    def _receive(
        self, data: bytes, *, line_bps: int | None = None, received_at: float | None = None
    ) -> Any:
        arrived = received_at or time.perf_counter()
        with self._lock:
            before = {i: self._motors[i].table.get("goal_position") for i in self.goal_ids}
            replies = self._original(data, line_bps=line_bps, received_at=received_at)
            packets = self._decoder.feed(data)
            positions = {i: self._motors[i].present_position_deg for i in self.read_ids}
            after = {i: self._motors[i].table.get("goal_position") for i in self.goal_ids}
        for packet in packets:
            if (
                isinstance(packet, InstructionPacket)
                and packet.instruction in READS
                and _read_address(self.bus.protocol, packet) == self._present
                and replies
            ):
                sent = replies[-1].send_at or time.perf_counter()
                self.reads.append((sent, positions))
        for motor_id, raw in after.items():
            if raw != before[motor_id]:
                self.goals.append((arrived, motor_id, self._motors[motor_id].goal_position_deg))
        return replies

    def read_rate_hz(self, start: float, end: float) -> float:
        """Present reads per second in ``[start, end]``."""
        count = sum(1 for t, _ in self.reads if start <= t <= end)
        return count / (end - start) if end > start else 0.0


class Hand:
    """Moves some virtual servos (motor frame) by hand: strokes, then steps.

    Args:
        motors: joint name -> its virtual servo.
        ranges: joint name -> (low, high) motor-frame degrees the hand stays within.
        seed: the strokes' and steps' random generator seed.
    """

    def __init__(
        self,
        motors: Mapping[str, VirtualMotor],
        ranges: Mapping[str, tuple[float, float]],
        seed: int = 17,
    ) -> None:
        self.motors = dict(motors)
        self.ranges = dict(ranges)
        self.random = random.Random(seed)
        self.position = {name: (low + high) / 2 for name, (low, high) in self.ranges.items()}
        self.steps: list[tuple[float, dict[str, float]]] = []
        self._lock = threading.Lock()

    def put(self, positions: Mapping[str, float]) -> None:
        """Put the joints there now."""
        with self._lock:
            for name, value in positions.items():
                self.motors[name].move_by_hand(value)
                self.position[name] = value

    def now(self) -> dict[str, float]:
        """Where the hand holds each joint (motor frame)."""
        with self._lock:
            return dict(self.position)

    def strokes(self, duration_s: float, stop: threading.Event | None = None) -> None:
        """Smooth strokes for ``duration_s``, updated at about 200 Hz."""
        plans = {name: self._plan(name, duration_s) for name in self.motors}
        start = time.perf_counter()
        while (t := time.perf_counter() - start) < duration_s:
            if stop is not None and stop.is_set():
                return
            self.put({name: _at(plan, t) for name, plan in plans.items()})
            time.sleep(0.004)

    def _plan(self, name: str, duration_s: float) -> list[tuple[float, MinimumJerk]]:
        low, high = self.ranges[name]
        t, here, plan = 0.0, self.position[name], []
        while t < duration_s:
            target = self.random.uniform(low, high)
            distance = abs(target - here)
            if distance < 5.0:
                continue
            span = min(distance, 60.0)
            target = here + math.copysign(span, target - here)
            speed = self.random.uniform(20.0, 70.0)  # mean speed of a stroke, deg/s
            segment = MinimumJerk(here, target, max(0.4, span / speed))
            plan.append((t, segment))
            t += segment.duration_s + self.random.uniform(0.0, 0.3)
            here = target
        return plan

    def step(self, count: int, period_s: float = STEP_S) -> None:
        """``count`` jumps, one every ``period_s``, each joint to a new value ≥ 8° away."""
        for _ in range(count):
            targets = {}
            for name, (low, high) in self.ranges.items():
                while True:
                    value = round(self.random.uniform(low, high), 1)
                    if abs(value - self.position[name]) >= 8.0:
                        break
                targets[name] = value
            self.put(targets)
            self.steps.append((time.perf_counter(), targets))
            time.sleep(period_s)


def _at(plan: list[tuple[float, MinimumJerk]], t: float) -> float:
    current = plan[0][1].start
    for start, segment in plan:
        if t < start:
            return current
        if t <= start + segment.duration_s:
            return segment.position(t - start)
        current = segment.goal
    return current


def latencies(
    hand: Hand,
    leader: BusProbe,
    follower: BusProbe,
    leader_ids: Mapping[str, int],
    follower_of: FollowerOf,
    tolerance: float,
) -> list[float]:
    """Read → goal latencies (s) of every step and joint.

    Args:
        hand: the hand that stepped.
        leader: the probe logging the leader's reads.
        follower: the probe logging the follower's goals.
        leader_ids: leader joint -> servo id.
        follower_of: leader joint -> (follower servo id, leader motor deg -> follower goal deg).
        tolerance: how close a goal must be to the expected one (degrees).
    """
    out = []
    for (t_step, targets), next_step in zip(hand.steps, [*hand.steps[1:], None], strict=True):
        end = next_step[0] if next_step is not None else math.inf
        for name, value in targets.items():
            ident = leader_ids[name]
            read_at = next(
                (t for t, pos in leader.reads if t >= t_step and abs(pos[ident] - value) < 0.6),
                None,
            )
            if read_at is None or read_at >= end:
                continue
            follower_id, expected = follower_of[name]
            goal = expected(value)
            wrote_at = next(
                (
                    t
                    for t, i, g in follower.goals
                    if i == follower_id and t >= read_at and t < end and abs(g - goal) <= tolerance
                ),
                None,
            )
            if wrote_at is not None:
                out.append(wrote_at - read_at)
    return out


class Tracker:
    """Samples the follower's horns against the hand at ``SAMPLE_HZ`` (follower motor frame)."""

    def __init__(self, hand: Hand, follower: VirtualBus, follower_of: FollowerOf) -> None:
        self.hand = hand
        self.follower = follower
        self.follower_of = dict(follower_of)
        self.errors: list[float] = []
        self.by_joint: dict[str, list[float]] = {name: [] for name in self.follower_of}
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)

    def __enter__(self) -> Tracker:
        self._thread.start()
        return self

    def __exit__(self, *_: object) -> None:
        self._stop.set()
        self._thread.join(2.0)

    def _run(self) -> None:
        motors = {m.id: m for m in self.follower.motors}
        while not self._stop.wait(1.0 / SAMPLE_HZ):
            hand = self.hand.now()
            with self.follower.motors[0].lock:
                self.follower.advance()
                present = {i: motors[i].present_position_deg for i, _ in self.follower_of.values()}
            for name, (ident, expected) in self.follower_of.items():
                error = present[ident] - expected(hand[name])
                self.errors.append(error)
                self.by_joint[name].append(error)

    def rms(self, errors: list[float] | None = None) -> float:
        """Root mean square of every sample's error (or of ``errors``), degrees."""
        values = self.errors if errors is None else errors
        if not values:
            return math.nan
        return math.sqrt(sum(e * e for e in values) / len(values))

    def rms_by_joint(self) -> dict[str, float]:
        """Each joint's RMS error (degrees)."""
        return {name: self.rms(errors) for name, errors in self.by_joint.items()}
