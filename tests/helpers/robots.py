"""Robot test helpers: simulated robots built the one way (``poppy_core.robot``)."""

from __future__ import annotations

from poppy_core.robot import Robot, from_profile


def sim_ergo_jr() -> Robot:
    """A simulated Ergo Jr (ideal servos, in-process link) without its camera."""
    return from_profile("ergo-jr", sim=True, sensors=False)
