"""Attach a robot's creature behaviours at run time, so ``robot`` never imports ``creatures``.

``creatures`` sits above ``robot`` (it builds on ``motion``), yet ``from_config`` must give a
Poppy robot its creature: primitives, postures, chains. The link is an entry point in the
``module:function`` form of Python packaging, resolved with ``importlib`` when a robot is built:
``CREATURE_HOOK`` names ``poppy_core.creatures.attach:attach_behaviours``, which looks at the
config (profile kind, or pypot motor names) and attaches the matching creature, or the kinematic
chains the config describes for any other robot. Another package may pass its own hook.
``MANAGER_HOOK`` reaches pypot's ``robot._primitive_manager`` (in ``motion``) the same way.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from poppy_core.robot.robot import Robot

CREATURE_HOOK = "poppy_core.creatures.attach:attach_behaviours"
MANAGER_HOOK = "poppy_core.motion.manager:primitive_manager"
"""The robot's primitive manager (``robot._primitive_manager``): ``motion`` sits above ``robot``."""

Hook = Callable[..., Any]


def resolve_hook(entry: str) -> Hook:
    """The function an entry point ``"package.module:function"`` names."""
    module_name, _, attribute = entry.partition(":")
    target: Any = importlib.import_module(module_name)
    for part in attribute.split("."):
        target = getattr(target, part)
    if not callable(target):
        raise TypeError(f"{entry} is not callable")
    return target  # type: ignore[no-any-return]


def attach_behaviours(
    robot: Robot, *, start_defaults: bool = True, hook: str = CREATURE_HOOK
) -> None:
    """Attach what the robot's config makes it (a creature's behaviours, or its chains).

    Args:
        robot: a robot built by ``from_config``.
        start_defaults: start the primitives the creature starts by default.
        hook: the entry point called as ``hook(robot, start_defaults=...)``.
    """
    resolve_hook(hook)(robot, start_defaults=start_defaults)
