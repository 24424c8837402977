"""Build a robot and attach its creature's behaviours: ``from_profile`` and ``from_config``."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from poppy_core.creatures.registry import attach_creature, detect_kind
from poppy_core.motion.chains import attach_chains
from poppy_core.robot import Robot
from poppy_core.robot import from_config as build_from_config
from poppy_core.robot import from_profile as build_from_profile
from poppy_core.robot.config_io import ConfigSource, as_config
from poppy_core.robot.factory import SimMode


def _attached(robot: Robot, start_defaults: bool) -> Robot:
    kind = detect_kind(robot.config) if robot.config is not None else None
    try:
        if kind is None:
            attach_chains(robot)  # a robot of its own: the chains its config describes
        else:
            attach_creature(robot, kind, start_defaults=start_defaults)
    except BaseException:
        robot.close()
        raise
    return robot


def from_config(
    config: ConfigSource,
    sim: SimMode = False,
    *,
    start_defaults: bool = True,
    **options: Any,
) -> Robot:
    """``poppy_core.robot.from_config`` plus the creature's behaviours when it names one.

    The creature is the config's profile kind, or (pypot JSON without header) the one whose
    motor names it has; other robots get the kinematic chains their config describes.

    Args:
        config: the config, a dict or a file path.
        sim: see ``poppy_core.robot.from_config``.
        start_defaults: start the primitives the creature starts by default.
        **options: passed to ``poppy_core.robot.from_config``.

    Returns:
        The running robot, with ``robot.creature`` and its primitives for a known creature.
    """
    cfg = as_config(config)
    return _attached(build_from_config(cfg, sim, **options), start_defaults)


def from_profile(
    name: str,
    port: str | Mapping[str, str] | None = None,
    sim: SimMode = False,
    *,
    start_defaults: bool = True,
    **options: Any,
) -> Robot:
    """``poppy_core.robot.from_profile`` plus the creature's behaviours (see ``from_config``).

    Args:
        name: the profile name (``"ergo-jr"``, ``"torso"``, ``"humanoid"``...).
        port: the port (one controller) or controller name -> port; None keeps the profile's.
        sim: serve the motors from emulators (True/``"ideal"`` or ``"mujoco"``).
        start_defaults: start the primitives the creature starts by default.
        **options: passed to ``poppy_core.robot.from_config``.
    """
    return _attached(build_from_profile(name, port, sim, **options), start_defaults)
