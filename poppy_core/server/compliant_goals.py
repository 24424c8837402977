"""Goals sent to compliant motors: refused on the v1 API, logged once per compliance period.

A compliant motor has its torque off: a goal written to it is kept by the motor but moves
nothing. pypot's routes, Snap! and ZMQ answer such goals as pypot does (done, 200); the v1 API
refuses them (409) so that a client learns why nothing moves. Either way the log says it once
per motor each time the motor is found compliant after being stiff.
"""

from __future__ import annotations

import logging
from collections.abc import Iterable, Mapping
from typing import Any

from poppy_core.robot import Motor
from poppy_core.server.errors import ApiError

logger = logging.getLogger(__name__)

GOAL_REGISTERS = frozenset({"goal_position"})
"""The registers whose values move a stiff motor."""


class CompliantMotorError(ApiError):
    """A goal for motors that are compliant (torque off), so it would move nothing: a 409."""

    def __init__(self, names: list[str]) -> None:
        which = ", ".join(names)
        verb = "is" if len(names) == 1 else "are"
        super().__init__(
            "conflict",
            f"{which} {verb} compliant (torque off), so a goal would not move it: make it "
            f'stiff first (PUT /api/v1/motors/{names[0]}/registers/compliant {{"value": false}})',
        )
        self.names = names


def goal_motors(commands: Mapping[str, Any]) -> list[str]:
    """The motors of ``{motor: {register: value}}`` given a goal without being made stiff by
    the same command (``compliant: false`` with it)."""
    return [
        name
        for name, registers in commands.items()
        if isinstance(registers, Mapping)
        and GOAL_REGISTERS.intersection(registers)
        and registers.get("compliant", True) is not False
    ]


class CompliantGoals:
    """The rule of goals to compliant motors, and which motors the log has named."""

    def __init__(self) -> None:
        self._named: set[str] = set()

    def refuse(self, motors: Iterable[Motor]) -> None:
        """Raise ``CompliantMotorError`` when one of ``motors`` is compliant.

        Raises:
            CompliantMotorError: the compliant ones, named.
        """
        compliant = [m for m in motors if m.compliant]
        for motor in compliant:
            self.note(motor)
        if compliant:
            raise CompliantMotorError([m.name for m in compliant])

    def note(self, motor: Motor) -> None:
        """A goal reached ``motor``: a WARNING the first time it is compliant since it was stiff."""
        if not motor.compliant:
            self._named.discard(motor.name)
        elif motor.name not in self._named:
            self._named.add(motor.name)
            logger.warning(
                "%s is compliant (torque off): the goals it gets do not move it until it is "
                "made stiff (compliant = false)",
                motor.name,
            )

    def stiff(self, names: Iterable[str]) -> None:
        """``names`` were made stiff: their next compliant period is named again."""
        self._named.difference_update(names)
