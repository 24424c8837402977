"""Which control-table registers the robot layer uses, per model family, and how they are batched.

Names here are the common names of ``poppy_core.models`` (aliases resolve per model): AX/MX
``cw_angle_limit`` is reached as ``min_position_limit``, X-series ``profile_velocity`` as
``moving_speed``, and so on.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from numbers import Real

from poppy_core import checks
from poppy_core.models import Register, ServoModel

# e-manual (MX-28/64/106 protocol 1, XL-320): P/I/D gains at addresses 26-29 (order differs).
MX_PID = ("p_gain", "i_gain", "d_gain")
# e-manual (X-series, Position P/I/D Gain at 84/82/80).
X_PID = ("position_p_gain", "position_i_gain", "position_d_gain")
# e-manual (AX-12A/AX-18A): CW/CCW compliance margin (26, 27) and slope (28, 29).
AX_MARGINS = ("cw_compliance_margin", "ccw_compliance_margin")
AX_SLOPES = ("cw_compliance_slope", "ccw_compliance_slope")
GAINS = (*MX_PID, *X_PID, *AX_MARGINS, *AX_SLOPES)

PRESENT = ("present_position", "present_speed", "present_load")
SENSORS = ("present_temperature", "present_voltage")
# Order matters: a goal is written before the torque is switched on in the same cycle.
GOALS = ("goal_position", "moving_speed", "torque_limit", "torque_enable", "led")
LIMITS = ("min_position_limit", "max_position_limit")

STATE = (*PRESENT, *SENSORS, *GOALS, *GAINS, *LIMITS, "return_delay_time")
"""Everything a motor reads once at start-up (from one read of its control table)."""


def pid_names(model: ServoModel) -> tuple[str, str, str] | None:
    """The (P, I, D) gain registers of ``model``, or None (AX servos have compliance instead)."""
    for names in (MX_PID, X_PID):
        if all(model.has_register(n) for n in names):
            return names
    return None


def has_compliance_slopes(model: ServoModel) -> bool:
    """True for models with compliance margins and slopes (AX)."""
    return all(model.has_register(n) for n in (*AX_MARGINS, *AX_SLOPES))


@dataclass(frozen=True)
class ReadBlock:
    """One contiguous read: registers of several motors sharing the same address layout.

    Attributes:
        address: first address read.
        length: bytes read.
        fields: (name, offset in the block, register) of each register.
    """

    address: int
    length: int
    fields: tuple[tuple[str, int, Register], ...]

    def decode(self, data: bytes) -> dict[str, float | int | bool | str]:
        """SI values (motor frame) of every field in ``data``."""
        out: dict[str, float | int | bool | str] = {}
        for name, offset, register in self.fields:
            out[name] = register.decode_si(data, start=register.address - offset)
        return out


# A block wider than this (bytes) is split into one read per register.
MAX_BLOCK_GAP = 8


def read_blocks(model: ServoModel, names: Sequence[str]) -> list[ReadBlock]:
    """How to read ``names`` (those ``model`` has) in as few contiguous reads as possible.

    Args:
        model: the servo model.
        names: common register names.

    Returns:
        One block when the registers sit close together (as they do in every Dynamixel
        table), else one block per register.
    """
    registers = [(n, model.register(n)) for n in names if model.has_register(n)]
    if not registers:
        return []
    start = min(r.address for _, r in registers)
    end = max(r.address + r.size for _, r in registers)
    useful = sum(r.size for _, r in registers)
    if end - start - useful <= MAX_BLOCK_GAP:
        fields = tuple((n, r.address - start, r) for n, r in registers)
        return [ReadBlock(start, end - start, fields)]
    return [ReadBlock(r.address, r.size, ((n, 0, r),)) for n, r in registers]


def decode_table(model: ServoModel, data: bytes, names: Sequence[str] = STATE) -> dict[str, object]:
    """SI values of ``names`` found in a control-table dump starting at address 0."""
    return dict(model.decode_table(data, names))


def si_range(register: Register) -> tuple[float, float]:
    """The (lowest, highest) SI value ``register`` holds; a speed or load its magnitude's."""
    return register.si_range()


def finite(value: object, field: str) -> float:
    """``value`` as a finite float (a huge integer is cut to ±2**40 before it meets ``float()``).

    Raises:
        ArgumentError: not a number, NaN or infinite.
    """
    if isinstance(value, Real) and not isinstance(value, bool):
        if isinstance(value, int):
            value = max(min(value, 1 << 40), -(1 << 40))
        number = float(value)
        if math.isfinite(number):
            return number
    return checks.number(value, field)  # raises: NaN, an infinity, not a number


def capped(register: Register, value: object, field: str) -> float:
    """``value`` as a number clamped to what ``register`` holds, as pypot capped it.

    Raises:
        ArgumentError: not a number, NaN or infinite (never clamped).
    """
    low, high = si_range(register)
    return min(max(finite(value, field), low), high)
