"""Motor specs: a motor or group name, a motor, or a list of them, resolved to a robot's motors."""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from typing import Protocol

from poppy_core.errors import ArgumentError, UnknownMotorError
from poppy_core.robot.motor import Motor


class NamedMotor(Protocol):
    """Anything standing for a motor by its name (a ``Motor``, a primitive's ``MockupMotor``)."""

    @property
    def name(self) -> str:
        """The motor's name in the robot."""
        ...


MotorSpec = str | NamedMotor | Iterable[str | NamedMotor]
"""A motor or group name, a motor, or a list of them (see ``Robot.motors_of``)."""


def is_motor(item: object) -> bool:
    """True for a motor-like object (a name and a present position), not a name."""
    return (
        not isinstance(item, str)
        and isinstance(getattr(item, "name", None), str)
        and hasattr(item, "present_position")
    )


def resolve(
    spec: MotorSpec | None, by_name: Mapping[str, Motor], groups: Mapping[str, Sequence[Motor]]
) -> list[Motor]:
    """The motors ``spec`` names, each once, in order (see ``Robot.motors_of``).

    Args:
        spec: the spec; None for every motor.
        by_name: the robot's motors by name, in config order.
        groups: the robot's groups by name.
    """
    if spec is None:
        return list(by_name.values())
    items: object = [spec] if isinstance(spec, str) or is_motor(spec) else spec
    if not isinstance(items, Iterable):
        raise ArgumentError(
            f"motors must be a name, a motor or a list of them, not {spec!r}",
            field="motors",
            value=spec,
        )
    chosen: list[Motor] = []
    for item in items:
        for motor in _named(item, by_name, groups):
            if motor not in chosen:
                chosen.append(motor)
    return chosen


def _named(
    item: object, by_name: Mapping[str, Motor], groups: Mapping[str, Sequence[Motor]]
) -> list[Motor]:
    if isinstance(item, str):
        if item in groups:
            return list(groups[item])
        if item in by_name:
            return [by_name[item]]
        known = list(by_name)
        group_names = ", ".join(groups) or "none"
        raise UnknownMotorError(
            f"no motor or group {item!r} (motors: {', '.join(known)}; groups: {group_names})",
            motor=item,
            known=known,
        )
    if is_motor(item):
        name = getattr(item, "name", None)
        if isinstance(name, str) and name in by_name:
            return [by_name[name]]
        known = list(by_name)
        raise UnknownMotorError(
            f"{name!r} is not a motor of this robot (motors: {', '.join(known)})",
            motor=str(name),
            known=known,
        )
    known = list(by_name)
    raise UnknownMotorError(
        f"{item!r} is not a motor name (motors: {', '.join(known)})",
        motor=str(item),
        known=known,
    )
