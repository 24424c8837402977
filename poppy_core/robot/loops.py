"""The register groups the sync loops run, after pypot's controllers (see ``robot.sync``)."""

from __future__ import annotations

from dataclasses import dataclass

from poppy_core.robot import registers as regs


@dataclass(frozen=True)
class LoopSpec:
    """One register group: its registers, direction and rate."""

    name: str
    registers: tuple[str, ...]
    write: bool
    rate_hz: float


BASE_LOOPS: tuple[LoopSpec, ...] = (
    LoopSpec("present", regs.PRESENT, False, 50.0),
    LoopSpec("goals", regs.GOALS, True, 50.0),
    LoopSpec("gains", regs.GAINS, True, 10.0),
    LoopSpec("limits", regs.LIMITS, True, 1.0),
    LoopSpec("sensors", regs.SENSORS, False, 1.0),
)
LIGHT_LOOPS: tuple[LoopSpec, ...] = (
    LoopSpec("present", ("present_position", "present_speed"), False, 50.0),
    LoopSpec("goals", regs.GOALS, True, 50.0),
    LoopSpec("gains", regs.GAINS, True, 10.0),
    LoopSpec("limits", regs.LIMITS, True, 1.0),
    LoopSpec("sensors", ("present_load", *regs.SENSORS), False, 1.0),
)


def loops_for(syncloop: str) -> tuple[LoopSpec, ...]:
    """The loops for a config's ``syncloop`` name (``LightDxlController`` → light, else base)."""
    return LIGHT_LOOPS if "light" in syncloop.lower() else BASE_LOOPS
