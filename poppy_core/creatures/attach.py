"""What ``poppy_core.from_config`` attaches to every robot it builds (its creature hook)."""

from __future__ import annotations

from poppy_core.creatures.registry import attach_creature, detect_kind
from poppy_core.motion.chains import attach_chains
from poppy_core.robot import Robot


def attach_behaviours(robot: Robot, *, start_defaults: bool = True) -> None:
    """Attach the robot's creature (named by its profile kind, or recognised by its motor names),
    or, for a robot of its own, the kinematic chains its config describes.

    Args:
        robot: a robot just built.
        start_defaults: start the primitives the creature starts by default.
    """
    kind = detect_kind(robot.config) if robot.config is not None else None
    if kind is None:
        attach_chains(robot)
    else:
        attach_creature(robot, kind, start_defaults=start_defaults)
