"""pypot's motor names and the model-specific registers: gains, compliance slopes, LED.

``PypotMotorMixin`` is a base of ``Motor`` (``poppy_core.robot.motor``): everything here is user
API, reached through the motor's ``MotorLink`` cache as the rest of ``Motor`` is.
"""

from __future__ import annotations

import functools

from poppy_core.errors import ArgumentError, RegisterError
from poppy_core.models import ServoModel
from poppy_core.robot import registers as regs
from poppy_core.robot.motor_link import MotorLink, SIValue
from poppy_core.trajectory import control_name


class PypotMotorMixin:
    """Gains, compliance slopes and LED (as the model has them), the register list, and pypot's
    other names for what ``Motor`` holds (``lower_limit``, ``control_mode``...)."""

    # Provided by Motor.
    name: str
    model: ServoModel
    wheel_mode: bool
    angle_limit: tuple[float, float]
    torque_limit: float
    _goto_behavior: str
    _link: MotorLink

    # -- gains and LED ---------------------------------------------------------------------

    @property
    def pid(self) -> tuple[float, float, float]:
        """(P, I, D) gains, in the model's e-manual scaling (MX, XL-320, X-series)."""
        names = self._pid_names()
        link = self._link
        return (link.number(names[0]), link.number(names[1]), link.number(names[2]))

    @pid.setter
    def pid(self, gains: tuple[float, float, float]) -> None:
        for name, value in zip(self._pid_names(), gains, strict=True):
            gain = regs.capped(self.model.register(name), value, f"{self.name}.pid")
            self._link.store(name, gain)  # pypot capped the gains to the registers' range too

    def _pid_names(self) -> tuple[str, str, str]:
        names = regs.pid_names(self.model)
        if names is None:
            raise RegisterError(
                f"{self.name}: {self.model.name} has no PID gains (use compliance_margin/slope)",
                register="pid",
                motor=self.name,
            )
        return names

    @property
    def compliance_margin(self) -> tuple[int, int]:
        """(CW, CCW) compliance margins (AX); set one number for both or a pair."""
        return self._pair(regs.AX_MARGINS)

    @compliance_margin.setter
    def compliance_margin(self, value: int | tuple[int, int]) -> None:
        self._set_pair(regs.AX_MARGINS, value)

    @property
    def compliance_slope(self) -> tuple[int, int]:
        """(CW, CCW) compliance slopes (AX); set one number for both or a pair."""
        return self._pair(regs.AX_SLOPES)

    @compliance_slope.setter
    def compliance_slope(self, value: int | tuple[int, int]) -> None:
        self._set_pair(regs.AX_SLOPES, value)

    def _pair(self, names: tuple[str, str]) -> tuple[int, int]:
        self._need_slopes()
        return int(self._link.number(names[0])), int(self._link.number(names[1]))

    def _set_pair(self, names: tuple[str, str], value: int | tuple[int, int]) -> None:
        self._need_slopes()
        pair = (value, value) if isinstance(value, int) else value
        for name, item in zip(names, pair, strict=True):
            self._link.store(name, item)

    def _need_slopes(self) -> None:
        if not regs.has_compliance_slopes(self.model):
            raise RegisterError(
                f"{self.name}: {self.model.name} has no compliance margin/slope (use pid)",
                register="compliance_margin",
                motor=self.name,
            )

    @property
    def led(self) -> SIValue:
        """LED state: a bool, or a colour name on the XL-320."""
        return self._link.get("led", False)

    @led.setter
    def led(self, value: SIValue) -> None:
        self._link.store("led", value)

    # -- pypot's names -----------------------------------------------------------------------

    @property
    def lower_limit(self) -> float:
        """The lower angle limit in degrees, user frame (pypot's name; ``angle_limit[0]``)."""
        return self.angle_limit[0]

    @lower_limit.setter
    def lower_limit(self, value: float) -> None:
        self.angle_limit = (float(value), self.angle_limit[1])

    @property
    def upper_limit(self) -> float:
        """The upper angle limit in degrees, user frame (pypot's name; ``angle_limit[1]``)."""
        return self.angle_limit[1]

    @upper_limit.setter
    def upper_limit(self, value: float) -> None:
        self.angle_limit = (self.angle_limit[0], float(value))

    @property
    def max_torque(self) -> float:
        """pypot's name for the torque limit (the RAM register; EEPROM Max Torque is left alone)."""
        return self.torque_limit

    @max_torque.setter
    def max_torque(self, value: float) -> None:
        self.torque_limit = value

    @property
    def goto_behavior(self) -> str:
        """The control of gotos that name none: ``"minjerk"`` or ``"dummy"`` (pypot's name)."""
        return self._goto_behavior

    @goto_behavior.setter
    def goto_behavior(self, value: str) -> None:
        try:
            self._goto_behavior = control_name(value)
        except ArgumentError as exc:
            raise RegisterError(
                f"{self.name}: goto_behavior must be 'minjerk' or 'dummy', not {value!r}",
                register="goto_behavior",
                motor=self.name,
            ) from exc

    @property
    def control_mode(self) -> str:
        """``"wheel"`` (endless turn) or ``"joint"`` (position control), as pypot names them."""
        return "wheel" if self.wheel_mode else "joint"

    # -- introspection -----------------------------------------------------------------------

    @property
    def registers(self) -> list[str]:
        """The attribute names this motor offers (they depend on the model)."""
        return list(self._register_names)

    @functools.cached_property
    def _register_names(self) -> tuple[str, ...]:
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
        if self.model.has_torque_limit:
            names += ["torque_limit", "max_torque"]
        if regs.pid_names(self.model) is not None:
            names.append("pid")
        if regs.has_compliance_slopes(self.model):
            names += ["compliance_margin", "compliance_slope"]
        return tuple(names)
