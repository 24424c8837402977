"""Plants: what moves the emulated horns (an ideal servo here; a physics engine can plug in)."""

from __future__ import annotations

import math
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


class IdealPlant:
    """An ideal servo: moves toward its goal at its moving speed, no inertia, no load.

    - torque on: the position goes toward the goal (clamped to the angle limits) at the moving
      speed (0 = the model's no-load speed, never faster than it); present speed is that speed
      while moving, 0 once there; ``moving`` is set while the goal is not reached;
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
                position = goal
            else:
                position += math.copysign(max_step, delta)
                speed = math.copysign(motor.speed_limit_dps, delta)
                moving = True
            if hand is not None:
                push = max(-1.0, min(1.0, (hand - position) / STALL_SPAN_DEG))
                load = -push * motor.torque_limit_pct
        motor.set_state(position, speed, load, moving)
        self._position[key] = position
        self._written[key] = motor.present_position_deg
