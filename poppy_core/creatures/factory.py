"""``from_profile`` and ``from_config`` of earlier releases: aliases of ``poppy_core.robot``'s.

``poppy_core.robot.from_config`` attaches the creature itself (``creatures.attach``, reached
through ``robot.creature_hook``); these keep their signatures for code that imports them here.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from poppy_core.robot import Robot
from poppy_core.robot import from_config as build_from_config
from poppy_core.robot import from_profile as build_from_profile
from poppy_core.robot.config_io import ConfigSource
from poppy_core.robot.factory import SimMode


def from_config(
    config: ConfigSource,
    sim: SimMode = False,
    *,
    start_defaults: bool = True,
    **options: Any,
) -> Robot:
    """``poppy_core.robot.from_config`` (which attaches the creature's behaviours).

    Args:
        config: the config, a dict or a file path.
        sim: see ``poppy_core.robot.from_config``.
        start_defaults: start the primitives the creature starts by default.
        **options: passed to ``poppy_core.robot.from_config``.

    Returns:
        The running robot, with ``robot.creature`` and its primitives for a known creature.
    """
    return build_from_config(config, sim, start_defaults=start_defaults, **options)


def from_profile(
    name: str,
    port: str | Mapping[str, str] | None = None,
    sim: SimMode = False,
    *,
    start_defaults: bool = True,
    **options: Any,
) -> Robot:
    """``poppy_core.robot.from_profile`` (which attaches the creature's behaviours).

    Args:
        name: the profile name (``"ergo-jr"``, ``"torso"``, ``"humanoid"``...).
        port: the port (one controller) or controller name -> port; None keeps the profile's.
        sim: serve the motors from emulators (True/``"ideal"`` or ``"mujoco"``).
        start_defaults: start the primitives the creature starts by default.
        **options: passed to ``poppy_core.robot.from_config``.
    """
    return build_from_profile(name, port, sim, start_defaults=start_defaults, **options)
