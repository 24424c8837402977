"""Plants: what moves the emulated horns (an ideal servo here; a physics engine can plug in)."""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Sequence
from typing import Protocol, runtime_checkable

from poppy_core.emulator.motor import VirtualMotor


@runtime_checkable
class Plant(Protocol):
    """The physical side of the emulator.

    A plant reads what the motors are told (``torque_enabled``, ``goal_position_deg``,
    ``speed_limit_dps``, or any register through ``motor.table``) and writes back what they
    sense with ``motor.set_state(position_deg, speed_dps, load_pct, moving)``. The bus calls
    :meth:`step` with the time elapsed since the previous step, before each instruction it
    handles and when asked (``VirtualBus.advance``). A plant that owns the joint state (a
    physics engine) also sets ``motor.hand_mover`` in :meth:`attach` so that
    ``motor.move_by_hand`` moves its joint.
    """

    def attach(self, motors: Sequence[VirtualMotor]) -> None:
        """Take charge of ``motors`` (called once by the bus, before any step)."""
        ...

    def step(self, dt_s: float) -> None:
        """Advance the physical state by ``dt_s`` seconds."""
        ...


HAND_FRICTION_PCT = 2.0
"""Present load of a compliant horn while a hand moves it (percent, against the motion)."""
STALL_SPAN_DEG = 5.0
"""How far a hand pulls a stiff horn away from its position for the full torque limit."""
SPEED_WINDOW_S = 0.1
"""A stiff horn's present speed is its mean velocity over this last stretch of time."""


class IdealPlant:
    """An ideal servo: moves toward its goal at its moving speed, no inertia, no load.

    - torque on: the position goes toward the goal (clamped to the angle limits) at the moving
      speed (0 = the model's no-load speed, never faster than it); present speed is the horn's
      mean velocity over the last ``SPEED_WINDOW_S`` (the moving speed during a long move, 0
      once still; a goto's goal moved a little at each step reads as the goto's speed, not 0:
      the horn reaches each of those goals within the step); ``moving`` is set while the goal
      is not reached;
    - torque off (compliant): the horn stays where it is (or where it was put by hand);
    - present load is 0, unless a hand holds the horn (``motor.hand_deg``, see
      ``poppy_core.emulator.hand``): a compliant horn follows the hand, its present speed is
      the hand's and its load a small ``HAND_FRICTION_PCT`` against the motion; a stiff horn
      goes on toward its goal and its load resists the hand, from 0 to the torque limit as the
      hand pulls ``STALL_SPAN_DEG`` or more away from where the horn is (the sign opposes the
      hand: a hand pushing toward higher angles reads a negative load).

    Positions are integrated in floating point, so slow motions at small steps are not lost to
    the register's resolution; a position changed in the table from outside (by hand) is picked
    up at the next step.
    """

    def __init__(self) -> None:
        self._motors: list[VirtualMotor] = []
        self._position: dict[int, float] = {}
        self._written: dict[int, float] = {}
        self._clock = 0.0
        self._moves: dict[int, deque[tuple[float, float, float]]] = {}
        """Per motor, its recent stretches of motion: (start s, end s, velocity °/s)."""

    def attach(self, motors: Sequence[VirtualMotor]) -> None:
        """Take charge of ``motors``."""
        self._motors = list(motors)
        for motor in self._motors:
            self._position[id(motor)] = motor.present_position_deg
            self._written[id(motor)] = motor.present_position_deg

    def step(self, dt_s: float) -> None:
        """Advance every motor by ``dt_s`` seconds."""
        if dt_s < 0:
            return
        for motor in self._motors:
            with motor.lock:
                self._step_motor(motor, dt_s)
        self._clock += dt_s

    def _mean_speed(self, key: int, moved: float, moving_s: float, dt_s: float) -> float:
        """The mean velocity over the last ``SPEED_WINDOW_S``, once this step moved ``moved``
        degrees in its first ``moving_s`` seconds (of ``dt_s``)."""
        moves = self._moves.setdefault(key, deque())
        if moved:
            moves.append((self._clock, self._clock + moving_s, moved / moving_s))
        end = self._clock + dt_s
        start = end - SPEED_WINDOW_S
        while moves and moves[0][1] <= start:
            moves.popleft()
        if not moves:
            return 0.0
        travelled = sum(v * (min(b, end) - max(a, start)) for a, b, v in moves if b > start)
        return travelled / min(SPEED_WINDOW_S, end)

    def _step_motor(self, motor: VirtualMotor, dt_s: float) -> None:
        key = id(motor)
        table_position = motor.present_position_deg
        position = self._position.get(key, table_position)
        if not math.isclose(table_position, self._written.get(key, table_position), abs_tol=1e-9):
            position = table_position  # moved by hand, reset or written from outside
        speed = 0.0
        load = 0.0
        moving = False
        hand = motor.hand_deg
        if hand is not None and not motor.torque_enabled:
            speed = motor.hand_speed_dps
            load = -math.copysign(HAND_FRICTION_PCT, speed) if abs(speed) > 1e-6 else 0.0
            position = hand
        elif motor.torque_enabled:
            low, high = motor.position_limits_deg()
            goal = min(max(motor.goal_position_deg, low), high)
            delta = goal - position
            max_step = motor.speed_limit_dps * dt_s
            if abs(delta) <= max_step or abs(delta) < 1e-9:
                moved, moving_s = delta, abs(delta) / motor.speed_limit_dps
                position = goal
            else:
                moved, moving_s = math.copysign(max_step, delta), dt_s
                position += moved
                moving = True
            speed = self._mean_speed(key, moved if abs(moved) >= 1e-9 else 0.0, moving_s, dt_s)
            if hand is not None:
                push = max(-1.0, min(1.0, (hand - position) / STALL_SPAN_DEG))
                load = -push * motor.torque_limit_pct
        motor.set_state(position, speed, load, moving)
        self._position[key] = position
        self._written[key] = motor.present_position_deg
