"""``MotorGroup``: a named group of a robot's motors that sets all of them at once."""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from typing import Any

from poppy_core import checks
from poppy_core.errors import ArgumentError, UnknownMotorError
from poppy_core.robot.goto import GotoHandle
from poppy_core.robot.motor import Motor
from poppy_core.robot.motor_link import link_of

GROUP_SETTABLE = frozenset(
    {
        "compliant",
        "compliant_behavior",
        "goto_behavior",
        "goal_position",
        "goal_speed",
        "moving_speed",
        "torque_limit",
        "max_torque",
        "led",
        "pid",
    }
)
"""Motor attributes a group sets on each of its motors (``robot.head.compliant = False``)."""


class MotorGroup(list[Motor]):
    """A named group of motors (a list, as in pypot) that also acts on all its motors:
    ``group.compliant = False``, ``group.goto_position(0, 2)``, ``group.moving_speed = 50``.

    Args:
        name: the group's name.
        motors: its motors, in order.
    """

    name: str

    def __init__(self, name: str, motors: Iterable[Motor]) -> None:
        super().__init__(motors)
        object.__setattr__(self, "name", name)

    def __repr__(self) -> str:
        return f"<MotorGroup {self.name} {[m.name for m in self]}>"

    def __setattr__(self, attribute: str, value: Any) -> None:
        if attribute not in GROUP_SETTABLE:
            raise AttributeError(
                f"a motor group sets only {', '.join(sorted(GROUP_SETTABLE))}, not {attribute!r}"
            )
        for motor in self:
            setattr(motor, attribute, value)

    @property
    def compliant(self) -> bool:
        """True when every motor of the group is compliant."""
        return all(m.compliant for m in self)

    def goto_position(
        self,
        position: float | Mapping[str, float] | Sequence[float],
        duration: float,
        control: str | None = None,
        wait: bool = False,
    ) -> GotoHandle:
        """Move the group's motors together: one angle for all, a motor name -> angle mapping,
        or one angle per motor in the group's order (degrees, user frame).

        Raises:
            ArgumentError: a list of angles whose length is not the group's, an unknown control
                or a bad duration.
        """
        if isinstance(position, Mapping):
            targets = {self._member(n): degrees(n, p) for n, p in position.items()}
        elif isinstance(position, int | float):
            targets = {m: degrees(m.name, position) for m in self}
        else:
            values = list(position)
            if len(values) != len(self):
                raise ArgumentError(
                    f"group {self.name}: {len(values)} positions for {len(self)} motors",
                    field="position",
                    value=values,
                )
            targets = {m: degrees(m.name, p) for m, p in zip(self, values, strict=True)}
        if not self:
            return GotoHandle(0, 0.0)
        runner = link_of(self[0]).runner
        handle = runner.start(targets, duration, control)
        if wait:
            handle.wait()
        return handle

    def _member(self, name: str) -> Motor:
        for motor in self:
            if motor.name == name:
                return motor
        raise UnknownMotorError(
            f"group {self.name} has no motor {name!r} (motors: {', '.join(m.name for m in self)})",
            motor=name,
            known=[m.name for m in self],
        )


def degrees(name: str, value: object) -> float:
    """``value`` as a finite number of degrees for motor ``name``, or ``ArgumentError``.

    The rule is ``checks.number`` (finite, within ±``MAX_MAGNITUDE``): a sane goal beyond the
    angle limits is clamped later, a huge one is refused, on every surface.
    """
    try:
        number = float(value)  # type: ignore[arg-type]
    except OverflowError:  # an integer beyond a float's range: refused below as huge
        number = float("inf")
    except (TypeError, ValueError):
        raise ArgumentError(
            f"{name}: {value!r} is not a number of degrees", field=name, value=value, motor=name
        ) from None
    try:
        return checks.number(number, name)
    except ArgumentError as exc:
        raise ArgumentError(
            f"{name}: the target must be a finite number of degrees within "
            f"±{checks.MAX_MAGNITUDE:g}, got {value!r}",
            field=name,
            value=value,
            motor=name,
        ) from exc
