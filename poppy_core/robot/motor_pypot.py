"""pypot's motor names and the model-specific registers: gains, compliance slopes, LED.

``PypotMotorMixin`` is a base of ``Motor`` (``poppy_core.robot.motor``) and takes ``self`` as a
typed host Protocol, ``PypotMotorHost``, so mypy checks that ``Motor`` gives what it uses:
everything here is user API, reached through the motor's ``MotorLink`` cache as the rest of
``Motor`` is.
"""

from __future__ import annotations

import functools
from typing import Protocol

from poppy_core.errors import ArgumentError, MissingRegisterError, RegisterError
from poppy_core.models import ServoModel
from poppy_core.robot import registers as regs
from poppy_core.robot.motor_link import MotorLink, SIValue
from poppy_core.trajectory import control_name


class PypotMotorHost(Protocol):
    """What ``PypotMotorMixin`` needs of the motor it is mixed into (``Motor`` gives it)."""

    name: str
    model: ServoModel
    wheel_mode: bool
    _goto_behavior: str
    _link: MotorLink

    @property
    def angle_limit(self) -> tuple[float, float]:
        """(min, max) in degrees, user frame."""
        ...

    @angle_limit.setter
    def angle_limit(self, limits: tuple[float, float]) -> None: ...

    @property
    def torque_limit(self) -> float:
        """Torque limit in % (RAM)."""
        ...

    @torque_limit.setter
    def torque_limit(self, value: float) -> None: ...


class PypotMotorMixin:
    """Gains, compliance slopes and LED (as the model has them), the register list, and pypot's
    other names for what a ``PypotMotorHost`` (a ``Motor``) holds (``lower_limit``,
    ``control_mode``...)."""

    # -- gains and LED ---------------------------------------------------------------------

    @property
    def pid(self: PypotMotorHost) -> tuple[float, float, float]:
        """(P, I, D) gains, in the model's e-manual scaling (MX, XL-320, X-series)."""
        names = _pid_names(self)
        link = self._link
        return (link.number(names[0]), link.number(names[1]), link.number(names[2]))

    @pid.setter
    def pid(self: PypotMotorHost, gains: tuple[float, float, float]) -> None:
        for name, value in zip(_pid_names(self), gains, strict=True):
            gain = regs.capped(self.model.register(name), value, f"{self.name}.pid")
            self._link.store(name, gain)  # pypot capped the gains to the registers' range too

    @property
    def compliance_margin(self: PypotMotorHost) -> tuple[int, int]:
        """(CW, CCW) compliance margins (AX); set one number for both or a pair."""
        return _pair(self, regs.AX_MARGINS)

    @compliance_margin.setter
    def compliance_margin(self: PypotMotorHost, value: int | tuple[int, int]) -> None:
        _set_pair(self, regs.AX_MARGINS, value)

    @property
    def compliance_slope(self: PypotMotorHost) -> tuple[int, int]:
        """(CW, CCW) compliance slopes (AX); set one number for both or a pair."""
        return _pair(self, regs.AX_SLOPES)

    @compliance_slope.setter
    def compliance_slope(self: PypotMotorHost, value: int | tuple[int, int]) -> None:
        _set_pair(self, regs.AX_SLOPES, value)

    @property
    def led(self: PypotMotorHost) -> SIValue:
        """LED state: a bool, or a colour name on the XL-320."""
        return self._link.get("led", False)

    @led.setter
    def led(self: PypotMotorHost, value: SIValue) -> None:
        self._link.store("led", value)

    # -- pypot's names -----------------------------------------------------------------------

    @property
    def lower_limit(self: PypotMotorHost) -> float:
        """The lower angle limit in degrees, user frame (pypot's name; ``angle_limit[0]``)."""
        return self.angle_limit[0]

    @lower_limit.setter
    def lower_limit(self: PypotMotorHost, value: float) -> None:
        self.angle_limit = (float(value), self.angle_limit[1])

    @property
    def upper_limit(self: PypotMotorHost) -> float:
        """The upper angle limit in degrees, user frame (pypot's name; ``angle_limit[1]``)."""
        return self.angle_limit[1]

    @upper_limit.setter
    def upper_limit(self: PypotMotorHost, value: float) -> None:
        self.angle_limit = (self.angle_limit[0], float(value))

    @property
    def max_torque(self: PypotMotorHost) -> float:
        """pypot's name for the torque limit (the RAM register; EEPROM Max Torque is left alone)."""
        return self.torque_limit

    @max_torque.setter
    def max_torque(self: PypotMotorHost, value: float) -> None:
        self.torque_limit = value

    @property
    def goto_behavior(self: PypotMotorHost) -> str:
        """The control of gotos that name none: ``"minjerk"`` or ``"dummy"`` (pypot's name)."""
        return self._goto_behavior

    @goto_behavior.setter
    def goto_behavior(self: PypotMotorHost, value: str) -> None:
        try:
            self._goto_behavior = control_name(value)
        except ArgumentError as exc:
            raise RegisterError(
                f"{self.name}: goto_behavior must be 'minjerk' or 'dummy', not {value!r}",
                register="goto_behavior",
                motor=self.name,
            ) from exc

    @property
    def control_mode(self: PypotMotorHost) -> str:
        """``"wheel"`` (endless turn) or ``"joint"`` (position control), as pypot names them."""
        return "wheel" if self.wheel_mode else "joint"

    # -- introspection -----------------------------------------------------------------------

    @property
    def registers(self: PypotMotorHost) -> list[str]:
        """The attribute names this motor offers (they depend on the model)."""
        return list(_register_names(self.model))


def _pid_names(motor: PypotMotorHost) -> tuple[str, str, str]:
    names = regs.pid_names(motor.model)
    if names is None:
        raise MissingRegisterError(
            f"{motor.name}: {motor.model.name} has no PID gains (use compliance_margin/slope)",
            register="pid",
            motor=motor.name,
        )
    return names


def _pair(motor: PypotMotorHost, names: tuple[str, str]) -> tuple[int, int]:
    _need_slopes(motor)
    return int(motor._link.number(names[0])), int(motor._link.number(names[1]))


def _set_pair(motor: PypotMotorHost, names: tuple[str, str], value: int | tuple[int, int]) -> None:
    _need_slopes(motor)
    pair = (value, value) if isinstance(value, int) else value
    for name, item in zip(names, pair, strict=True):
        motor._link.store(name, item)


def _need_slopes(motor: PypotMotorHost) -> None:
    if not regs.has_compliance_slopes(motor.model):
        raise MissingRegisterError(
            f"{motor.name}: {motor.model.name} has no compliance margin/slope (use pid)",
            register="compliance_margin",
            motor=motor.name,
        )


@functools.cache
def _register_names(model: ServoModel) -> tuple[str, ...]:
    """The attribute names a motor of ``model`` offers (models are shared, immutable singletons)."""
    names = [
        "id",
        "name",
        "model",
        "orientation",
        "offset",
        "angle_limit",
        "present_position",
        "present_speed",
        "present_load",
        "present_temperature",
        "present_voltage",
        "goal_position",
        "goal_speed",
        "moving_speed",
        "compliant",
        "compliant_behavior",
        "led",
        "lower_limit",
        "upper_limit",
        "goto_behavior",
        "control_mode",
        "registers",
        "safe_compliant",
    ]
    if model.has_torque_limit:
        names += ["torque_limit", "max_torque"]
    if regs.pid_names(model) is not None:
        names.append("pid")
    if regs.has_compliance_slopes(model):
        names += ["compliance_margin", "compliance_slope"]
    return tuple(names)
