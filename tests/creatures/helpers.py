"""Helpers of the creature tests: waiting, virtual motors, positions."""

from __future__ import annotations

from typing import Any

from poppy_core.emulator import VirtualMotor
from poppy_core.robot import Robot
from tests.helpers.robots import reached
from tests.helpers.waiting import eventually as wait_until

__all__ = ["reached", "virtual", "wait_until"]


def virtual(robot: Robot, name: str) -> VirtualMotor:
    """The emulator's virtual motor behind motor ``name``."""
    assert robot.config is not None
    controller = robot.config.controller_of(name)
    assert controller is not None
    motor: VirtualMotor = robot.emulators[controller].bus.motor(robot.motor(name).id)
    return motor


def stop_all(robot: Robot) -> None:
    """Stop every attached primitive but the temperature monitor."""
    for name, primitive in zip(robot.primitive_names, robot.primitives, strict=True):
        if name != "temperature_monitoring":
            primitive.stop()


def positions(robot: Robot, names: Any = None) -> dict[str, float]:
    """Present positions by motor name."""
    chosen = names if names is not None else [m.name for m in robot.motors]
    return {n: robot.motor(n).present_position for n in chosen}
