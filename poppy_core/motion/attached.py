"""The primitives of a robot: attached by name (``robot.<name>``), and those running now."""

from __future__ import annotations

from typing import TYPE_CHECKING

from poppy_core.errors import ConfigError, UnknownPrimitiveError
from poppy_core.motion.manager import PrimitiveManager
from poppy_core.motion.primitive import Primitive
from poppy_core.robot.robot_pypot import MANAGER_KEY

if TYPE_CHECKING:
    from poppy_core.robot import Robot


def attach_primitive(robot: Robot, name: str, primitive: Primitive) -> None:
    """Make ``primitive`` reachable as ``robot.<name>`` and list it in ``robot.primitives``.

    Raises:
        ConfigError: the primitive acts on another robot, or ``name`` is taken or invalid.
    """
    if primitive.real_robot is not robot:
        raise ConfigError(f"primitive {name!r} was built for another robot", field=name)
    robot.attach_primitive(primitive, name)


def attached_primitives(robot: Robot) -> dict[str, Primitive]:
    """Name -> every primitive attached to ``robot``."""
    return {
        name: obj
        for name in robot.primitive_names
        if isinstance(obj := robot.extensions.get(name), Primitive)
    }


def attached_primitive(robot: Robot, name: str) -> Primitive:
    """The primitive attached to ``robot`` under ``name``.

    Raises:
        UnknownPrimitiveError: no such primitive (the attached ones are listed).
    """
    attached = attached_primitives(robot)
    found = attached.get(name)
    if found is None:
        known = list(attached)
        raise UnknownPrimitiveError(
            f"no primitive {name!r} (primitives: {', '.join(known) or 'none'})",
            name=str(name),
            known=known,
        )
    return found


def active_primitives(robot: Robot) -> list[Primitive]:
    """The primitives whose requests the manager combines now (attached or not)."""
    existing = robot.extensions.get(MANAGER_KEY)
    return existing.primitives if isinstance(existing, PrimitiveManager) else []
