"""Robot test helpers: simulated robots built the one way, and whether they reached a pose."""

from __future__ import annotations

from poppy_core import from_profile
from poppy_core.robot import Robot


def sim_ergo_jr() -> Robot:
    """A simulated Ergo Jr (ideal servos, in-process link) without its camera."""
    return from_profile("ergo-jr", sim=True, sensors=False)


def reached(robot: Robot, targets: dict[str, float], tolerance_deg: float = 3.0) -> bool:
    """True when every motor of ``targets`` is within ``tolerance_deg`` of its target."""
    return all(
        abs(robot.motor(n).present_position - v) <= tolerance_deg for n, v in targets.items()
    )
