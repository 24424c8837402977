"""MotorPort: one virtual motor's commands read, and its sensed state written, as raw table bytes.

The physics thread talks to every motor's control table hundreds of times a second. Going
through ``ControlTable.get_si``/``set_si`` (register lookup by name, range messages, one
slice per register) costs more than the physics itself, so a port resolves its registers once
and then:

- reads every command register with one ``struct.unpack_from`` over their span of the table;
  only when those raw values changed does it convert them to a :class:`Command` (with the same
  rules as ``VirtualMotor.goal_position_deg``, ``speed_limit_dps``, ``position_limits_deg``,
  ``torque_enabled`` and the ``torque_limit`` register);
- writes the sensed registers with one ``struct.pack_into`` per run of adjacent registers,
  encoding each value exactly as ``Register.from_si`` does; a value out of the register's range
  goes through ``ControlTable.set_si`` (which clamps it), as before.

The caller holds ``motor.lock`` around both calls.
"""

from __future__ import annotations

import math
import struct
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from operator import itemgetter
from typing import NamedTuple

from poppy_core.emulator.motor import VirtualMotor
from poppy_core.models.converters import Boolean, DirectionBit, Linear
from poppy_core.models.register import Register

# The registers a command is made of, and the sensed ones (names resolved through the model's
# aliases, e.g. cw_angle_limit for min_position_limit on protocol-1 models).
COMMAND_REGISTERS = (
    "torque_enable",
    "goal_position",
    "moving_speed",
    "min_position_limit",
    "max_position_limit",
    "torque_limit",
)
STATE_REGISTERS = ("present_position", "present_speed", "present_load", "moving")
_FORMATS = {
    (1, False): "B",
    (2, False): "H",
    (4, False): "I",
    (1, True): "b",
    (2, True): "h",
    (4, True): "i",
}

Encoder = Callable[[float], int]


class Command(NamedTuple):
    """What a motor's table asks of its joint, in the motor's own frame (degrees)."""

    torque_on: bool
    goal_deg: float
    speed_limit_dps: float
    torque_pct: float


def _encoder(register: Register) -> Encoder:
    """``register.from_si``, raising ValueError when the raw value is out of the register's
    range (the caller then goes through ``ControlTable.set_si``, which clamps)."""
    conversion, low, high = register.conversion, register.min_raw, register.max_raw
    if isinstance(conversion, Linear):
        scale, offset = conversion.scale, conversion.offset_raw

        def linear(value: float) -> int:
            raw = round(value / scale + offset)
            if not low <= raw <= high:
                raise ValueError("out of range")
            return raw

        return linear
    if isinstance(conversion, DirectionBit):
        step = conversion.scale

        def direction_bit(value: float) -> int:
            magnitude = round(abs(value) / step)
            raw = magnitude | 0x400 if math.copysign(1.0, value) < 0 else magnitude
            if magnitude > 0x3FF or not low <= raw <= high:
                raise ValueError("out of range")
            return raw

        return direction_bit
    if isinstance(conversion, Boolean) and low <= 0 and high >= 1:
        return lambda value: 1 if value else 0

    def generic(value: float) -> int:
        raw = conversion.from_si(value)
        if not low <= raw <= high:
            raise ValueError("out of range")
        return raw

    return generic


def _layout(registers: Sequence[Register]) -> str:
    """struct format reading ``registers`` (sorted by address) over their span, gaps skipped."""
    parts = ["<"]
    end = registers[0].address
    for register in registers:
        if register.address > end:
            parts.append(f"{register.address - end}x")
        parts.append(_FORMATS[(register.size, register.signed)])
        end = register.address + register.size
    return "".join(parts)


@dataclass(frozen=True)
class _Run:
    """Adjacent sensed registers written together with one ``struct.pack_into``."""

    address: int
    layout: str
    fields: tuple[tuple[int, Register, Encoder], ...]  # (index in the state tuple, ...)


class MotorPort:
    """Fast access to one motor's command and state registers (see the module doc).

    Args:
        motor: the virtual motor; its model's registers are resolved once here.
    """

    def __init__(self, motor: VirtualMotor) -> None:
        self.motor = motor
        table = motor.table
        found = {name: table.find(name) for name in COMMAND_REGISTERS}
        if not motor.model.has_torque_limit:
            found["torque_limit"] = None
        self._registers = {name: reg for name, reg in found.items() if reg is not None}
        ordered = sorted(
            {r.address: r for r in self._registers.values()}.values(), key=lambda r: r.address
        )
        self._read_at = ordered[0].address if ordered else 0
        self._read_layout = _layout(ordered) if ordered else "<"
        self._slot = {name: ordered.index(reg) for name, reg in self._registers.items()}
        # The goal changes at up to 50 Hz, the other registers seldom: a new goal alone
        # converts one register.
        goal_slot = self._slot.get("goal_position", -1)
        self._goal_slot = goal_slot
        rest = [i for i in range(len(ordered)) if i != goal_slot]
        self._rest: Callable[[tuple[int, ...]], object] = (
            itemgetter(*rest) if rest else (lambda raw: ())
        )
        self._last: tuple[int, ...] | None = None
        self._limits_deg = (0.0, 0.0)
        self._command_now = Command(False, 0.0, 0.0, 100.0)
        self._half_range_deg = motor.model.position_range_deg / 2
        self._no_load_dps = motor.model.no_load_speed_dps
        sensed = [(i, r) for i, n in enumerate(STATE_REGISTERS) if (r := table.find(n)) is not None]
        sensed.sort(key=lambda item: item[1].address)
        self._runs = self._group(sensed)

    @staticmethod
    def _group(sensed: list[tuple[int, Register]]) -> list[_Run]:
        runs: list[list[tuple[int, Register]]] = []
        for item in sensed:
            last = runs[-1][-1][1] if runs else None
            if last is not None and last.address + last.size == item[1].address:
                runs[-1].append(item)
            else:
                runs.append([item])
        return [
            _Run(
                run[0][1].address,
                _layout([r for _, r in run]),
                tuple((i, r, _encoder(r)) for i, r in run),
            )
            for run in runs
        ]

    def forget(self) -> None:
        """Make the next :meth:`read_command` convert the table even if it did not change."""
        self._last = None

    def read_command(self) -> Command | None:
        """The motor's command when its registers changed since the last call, else None."""
        raw = struct.unpack_from(self._read_layout, self.motor.table.data, self._read_at)
        last = self._last
        if raw == last:
            return None
        self._last = raw
        slot = self._goal_slot
        if last is not None and slot >= 0 and self._rest(raw) == self._rest(last):
            on, _, speed_dps, torque_pct = self._command_now
            command = Command(on, self._goal_deg(raw[slot]), speed_dps, torque_pct)
        else:
            command = self._command(raw, raw[slot] if slot >= 0 else 0)
        self._command_now = command
        return command

    def _si(self, raw: tuple[int, ...], name: str) -> float | None:
        register = self._registers.get(name)
        if register is None:
            return None
        value = register.to_si(raw[self._slot[name]])
        return float(value) if isinstance(value, int | float) else None

    def _goal_deg(self, goal_raw: int) -> float:
        """VirtualMotor.goal_position_deg, kept within the angle limits."""
        register = self._registers.get("goal_position")
        value = 0.0 if register is None else register.to_si(goal_raw)
        goal = float(value) if isinstance(value, int | float) else 0.0
        low, high = self._limits_deg
        return min(max(goal, low), high)

    def _command(self, raw: tuple[int, ...], goal_raw: int) -> Command:
        # Same rules as VirtualMotor.position_limits_deg / goal_position_deg / speed_limit_dps.
        low, high = self._si(raw, "min_position_limit"), self._si(raw, "max_position_limit")
        if low is None or high is None or low >= high:
            low, high = -self._half_range_deg, self._half_range_deg
        self._limits_deg = (low, high)
        speed = abs(self._si(raw, "moving_speed") or 0.0)
        speed_raw = raw[self._slot["moving_speed"]] if "moving_speed" in self._slot else 0
        limit = self._no_load_dps
        torque = self._si(raw, "torque_limit")
        enable = raw[self._slot["torque_enable"]] if "torque_enable" in self._slot else 0
        return Command(
            torque_on=bool(enable),
            goal_deg=self._goal_deg(goal_raw),
            speed_limit_dps=limit if speed_raw == 0 or speed == 0.0 else min(speed, limit),
            torque_pct=torque if torque is not None else 100.0,
        )

    def write_state(self, state: tuple[float, float, float, bool]) -> None:
        """Store (position °, speed °/s, load %, moving) in the sensed registers."""
        data = self.motor.table.data
        for run in self._runs:
            fields = run.fields
            try:
                if len(fields) == 1:
                    index, _, encode = fields[0]
                    struct.pack_into(run.layout, data, run.address, encode(state[index]))
                else:
                    raws = [encode(state[index]) for index, _, encode in fields]
                    struct.pack_into(run.layout, data, run.address, *raws)
            except (TypeError, ValueError, OverflowError):
                self._write_slowly(run, state)

    def _write_slowly(self, run: _Run, state: tuple[float, float, float, bool]) -> None:
        """One register at a time; a value out of range goes through ``set_si`` (clamped)."""
        table = self.motor.table
        for index, register, encode in run.fields:
            try:
                table.store(register, encode(state[index]))
            except (TypeError, ValueError, OverflowError):
                table.set_si(register.name, float(state[index]))
