"""``Motor``: one servo in SI units, with orientation, offset and limits, cached by the sync loops.

Frames (``poppy_core.robot.frames``): the *motor frame* is the servo's own (``poppy_core.models``
degrees, 0° mid-range); the *user frame* is what a robot script sees. With ``s = +1`` (direct)
or ``-1`` (indirect)::

    user = s * motor - offset          motor = s * (user + offset)

Speeds and loads flip their sign with the orientation. A ``Motor`` speaks the user frame,
angle limits included; a config's ``angle_limit`` is in the motor frame, as in pypot (what the
servo's EEPROM holds), and ``from_config`` converts it.

Nothing here touches the bus: reads return the values the sync loops last read, writes store the
value and mark it for the next write cycle (``take_pending``).
"""

from __future__ import annotations

import functools
import logging
from typing import TYPE_CHECKING, Literal

from poppy_core.errors import ArgumentError, RegisterError, RobotClosedError
from poppy_core.models import ServoModel
from poppy_core.robot import frames
from poppy_core.robot import registers as regs
from poppy_core.robot.goto import GotoHandle, GotoRunner
from poppy_core.robot.motor_cache import MotorCache, SIValue
from poppy_core.trajectory import control_name

if TYPE_CHECKING:
    from poppy_core.robot.config import MotorConfig

logger = logging.getLogger(__name__)

CompliantBehavior = Literal["dummy", "safe"]
BEHAVIORS: tuple[str, ...] = ("dummy", "safe")
# A motor stiffened by safe compliance goes compliant again once this far inside its limits.
SAFE_RELEASE_MARGIN_DEG = 1.0
FULL_TORQUE_PCT = 100.0
# poppy's gotos are smooth by default (pypot's motors default to 'dummy'; its Torso and Humanoid
# set 'minjerk'): the pypot creature classes set their creature's control.
DEFAULT_GOTO_BEHAVIOR = "minjerk"


class CompliantBehaviorSetting(str):
    """A motor's compliant behaviour: a string (``"dummy"``/``"safe"``) that can be called to set
    it, as the Poppy documentation writes ``robot.head_z.compliant_behavior('safe')``."""

    __slots__ = ("_motor",)
    _motor: Motor

    def __new__(cls, value: str, motor: Motor) -> CompliantBehaviorSetting:
        setting = super().__new__(cls, value)
        setting._motor = motor
        return setting

    def __call__(self, value: str) -> None:
        """Set the motor's compliant behaviour to ``value``."""
        self._motor.compliant_behavior = value


class Motor(MotorCache):
    """A servo on a robot: registers by name in SI units, user frame.

    Args:
        name: the motor's name in the robot.
        model: its servo model.
        id: its bus ID.
        orientation: ``"direct"`` or ``"indirect"`` (flips the sign of angles, speeds, loads).
        offset: degrees added to user positions before the orientation is applied.
        angle_limit: (min, max) in the user frame; None for the model's whole range.
        wheel_mode: a wheel: goals are not clamped and no limits are written.
        runner: the goto runner shared by the robot (a private one when None).
    """

    def __init__(
        self,
        name: str,
        model: ServoModel,
        id: int,
        *,
        orientation: Literal["direct", "indirect"] = "direct",
        offset: float = 0.0,
        angle_limit: tuple[float, float] | None = None,
        wheel_mode: bool = False,
        runner: GotoRunner | None = None,
    ) -> None:
        if orientation not in ("direct", "indirect"):
            raise RegisterError(
                f"{name}: orientation must be 'direct' or 'indirect', not {orientation!r}",
                register="orientation", motor=name,
            )
        super().__init__(name, model)
        self.id = id
        self.orientation: Literal["direct", "indirect"] = orientation
        self.offset = float(offset)
        self.wheel_mode = wheel_mode
        self._behavior: CompliantBehavior = "dummy"
        self._goto_behavior = DEFAULT_GOTO_BEHAVIOR
        self._goal_speed: float | None = None
        self._runner = runner if runner is not None else GotoRunner(name=f"goto {name}")
        self._closed = False
        # The motor-frame range a position limit register can hold (AX -150..149.7°).
        register = model.register("min_position_limit")
        ends = sorted(float(register.to_si(r)) for r in (register.min_raw, register.max_raw))
        self._range = (ends[0], ends[1])
        low, high = angle_limit if angle_limit is not None else self._user_range()
        self._limits = self._checked_limits(low, high)

    @classmethod
    def from_config(
        cls, name: str, config: MotorConfig, model: ServoModel, runner: GotoRunner | None = None
    ) -> Motor:
        """Build a motor from its config entry (``RobotConfig.motors[name]``).

        The entry's ``angle_limit`` is in the motor frame (pypot's); the motor's is in the user
        frame.
        """
        return cls(
            name,
            model,
            config.id,
            orientation=config.orientation,
            offset=config.offset,
            angle_limit=config.user_angle_limit,
            wheel_mode=config.wheel_mode,
            runner=runner,
        )

    def __repr__(self) -> str:
        return (
            f"<Motor {self.name} id={self.id} {self.model.name} "
            f"pos={self.present_position:.1f} compliant={self.compliant}>"
        )

    # -- frames ------------------------------------------------------------------------------

    @property
    def direct(self) -> bool:
        """True for the direct orientation."""
        return self.orientation == "direct"

    @property
    def _sign(self) -> float:
        return frames.sign_of(self.orientation)

    def to_user(self, motor_deg: float) -> float:
        """A motor-frame angle seen in the user frame."""
        return frames.to_user(motor_deg, self.orientation, self.offset)

    def to_motor(self, user_deg: float) -> float:
        """A user-frame angle in the motor frame."""
        return frames.to_motor(user_deg, self.orientation, self.offset)

    def _user_range(self) -> tuple[float, float]:
        ends = sorted(self.to_user(v) for v in self._range)
        return ends[0], ends[1]

    def motor_limits(self) -> tuple[float, float]:
        """The angle limits in the motor frame (min, max), kept inside the model's range."""
        low, high = self.config_limits()
        return max(low, self._range[0]), min(high, self._range[1])

    def config_limits(self) -> tuple[float, float]:
        """The angle limits in the motor frame, as a config's ``angle_limit`` gives them."""
        return frames.motor_limits(self._limits, self.orientation, self.offset)

    def _checked_limits(self, low: float, high: float) -> tuple[float, float]:
        if not low < high:
            raise RegisterError(
                f"{self.name}: angle limits must be (min, max) with min < max, got {low}, {high}",
                register="angle_limit", motor=self.name,
            )
        return float(low), float(high)

    # -- present values (read-only) --------------------------------------------------------------

    @property
    def present_position(self) -> float:
        """Position in degrees (user frame), as last read."""
        return self.to_user(self._number("present_position"))

    @property
    def present_speed(self) -> float:
        """Speed in deg/s (user frame sign), as last read."""
        return self._sign * self._number("present_speed")

    @property
    def present_load(self) -> float:
        """Load in % of the maximum (user frame sign; mA on XM430/XL330), as last read."""
        return self._sign * self._number("present_load")

    @property
    def present_temperature(self) -> float:
        """Temperature in °C, as last read (read at a low rate)."""
        return self._number("present_temperature")

    @property
    def present_voltage(self) -> float:
        """Supply voltage in V, as last read (read at a low rate)."""
        return self._number("present_voltage")

    temperature = present_temperature
    voltage = present_voltage
    load = present_load

    # -- goals -------------------------------------------------------------------------------

    @property
    def goal_position(self) -> float:
        """Goal in degrees (user frame); set values are clamped to ``angle_limit``."""
        return self.to_user(self._number("goal_position"))

    @goal_position.setter
    def goal_position(self, value: float) -> None:
        self._runner.cancel(self)
        self.set_goal(value)

    def set_goal(self, user_deg: float) -> None:
        """Set the goal position without cancelling a running goto (used by the goto runner)."""
        low, high = self._limits
        target = float(user_deg) if self.wheel_mode else min(max(float(user_deg), low), high)
        motor_deg = self.to_motor(target)
        bottom, top = self._range if self.wheel_mode else self.motor_limits()
        self._store("goal_position", min(max(motor_deg, bottom), top))
        self._goal_speed = None

    @property
    def moving_speed(self) -> float:
        """Speed limit toward the goal in deg/s (0 = the servo's full speed)."""
        return abs(self._number("moving_speed"))

    @moving_speed.setter
    def moving_speed(self, value: float) -> None:
        if value < 0:
            raise RegisterError(
                f"{self.name}: moving_speed is a magnitude (>= 0), got {value}",
                register="moving_speed", motor=self.name,
            )
        self._store("moving_speed", float(value))

    @property
    def goal_speed(self) -> float:
        """Speed control in deg/s (user frame sign): 0 unless set since the last goal position.

        Setting it sends the goal to the limit in that direction with ``moving_speed = |speed|``,
        so the motor turns at that speed and still stops at its angle limit; 0 stops it where it
        is.
        """
        return self._goal_speed if self._goal_speed is not None else 0.0

    @goal_speed.setter
    def goal_speed(self, value: float) -> None:
        self._runner.cancel(self)
        speed = float(value)
        register = self.model.register("moving_speed")
        smallest = abs(float(register.to_si(1)))  # 0 means full speed: never send it
        if abs(speed) < smallest / 2:
            self.set_goal(self.present_position)
            self._goal_speed = 0.0
            return
        magnitude = min(max(abs(speed), smallest), self.model.no_load_speed_dps)
        low, high = self._limits if not self.wheel_mode else self._user_range()
        self.moving_speed = magnitude
        self.set_goal(high if speed > 0 else low)
        self._goal_speed = magnitude if speed > 0 else -magnitude

    @property
    def torque_limit(self) -> float:
        """Torque limit in % (RAM); always 100 on models without one (X-series)."""
        if not self.model.has_torque_limit:
            return FULL_TORQUE_PCT
        return self._number("torque_limit")

    @torque_limit.setter
    def torque_limit(self, value: float) -> None:
        if not self.model.has_torque_limit:
            raise RegisterError(
                f"{self.name}: {self.model.name} has no torque limit register",
                register="torque_limit", motor=self.name,
            )
        self._store("torque_limit", float(value))

    max_torque = torque_limit
    """pypot's name for the torque limit (the RAM register; EEPROM Max Torque is left alone)."""

    # -- compliance --------------------------------------------------------------------------

    @property
    def compliant(self) -> bool:
        """True when the motor is meant to be free (torque off)."""
        return self._compliant

    @compliant.setter
    def compliant(self, value: bool) -> None:
        with self._lock:
            self._compliant = bool(value)
            if self._compliant:
                self._set_torque(False)
                self._apply_safe_compliance()
            elif not self._torque:
                self.set_goal(self.present_position)
                self._set_torque(True)

    @property
    def torque_enabled(self) -> bool:
        """True when the torque is (meant to be) on, including a safe-compliance stiffening."""
        return self._torque

    def _set_torque(self, on: bool) -> None:
        self._torque = on
        self._store("torque_enable", on)

    @property
    def compliant_behavior(self) -> CompliantBehaviorSetting:
        """``"dummy"``: compliant means free; ``"safe"``: free inside the limits, stiff at them.

        Set it (``m.compliant_behavior = "safe"``) or call it as the Poppy documentation does
        (``m.compliant_behavior("safe")``); read, it compares and prints as the name.
        """
        return CompliantBehaviorSetting(self._behavior, self)

    @compliant_behavior.setter
    def compliant_behavior(self, value: str) -> None:
        if value not in BEHAVIORS:
            raise RegisterError(
                f"{self.name}: compliant behavior must be 'dummy' or 'safe', not {value!r}",
                register="compliant_behavior", motor=self.name,
            )
        with self._lock:
            self._behavior = "safe" if value == "safe" else "dummy"
            if self._compliant:
                self._set_torque(False)
                self._apply_safe_compliance()

    @property
    def safe_compliant(self) -> bool:
        """pypot's flag: True when the compliant behaviour is ``"safe"``."""
        return self._behavior == "safe"

    @safe_compliant.setter
    def safe_compliant(self, value: bool) -> None:
        self.compliant_behavior = "safe" if value else "dummy"

    def _apply_safe_compliance(self) -> None:
        """Safe compliance: stiffen a compliant motor pushed past a limit, free it once back."""
        if not (self._compliant and self._behavior == "safe") or self.wheel_mode:
            return
        if "present_position" not in self._values:
            return
        position = self.present_position
        low, high = self._limits
        if not self._torque and not low <= position <= high:
            logger.debug("%s pushed past its limits (%.1f°): holding it", self.name, position)
            self.set_goal(position)
            self._set_torque(True)
        elif self._torque and low + SAFE_RELEASE_MARGIN_DEG <= position <= high - (
            SAFE_RELEASE_MARGIN_DEG
        ):
            self._set_torque(False)

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
                register="goto_behavior", motor=self.name,
            ) from exc

    # -- limits ------------------------------------------------------------------------------

    @property
    def lower_limit(self) -> float:
        """The lower angle limit in degrees, user frame (pypot's name; ``angle_limit[0]``)."""
        return self._limits[0]

    @lower_limit.setter
    def lower_limit(self, value: float) -> None:
        self.angle_limit = (float(value), self._limits[1])

    @property
    def upper_limit(self) -> float:
        """The upper angle limit in degrees, user frame (pypot's name; ``angle_limit[1]``)."""
        return self._limits[1]

    @upper_limit.setter
    def upper_limit(self, value: float) -> None:
        self.angle_limit = (self._limits[0], float(value))

    @property
    def control_mode(self) -> str:
        """``"wheel"`` (endless turn) or ``"joint"`` (position control), as pypot names them."""
        return "wheel" if self.wheel_mode else "joint"

    @property
    def angle_limit(self) -> tuple[float, float]:
        """(min, max) in degrees, user frame; setting it also updates the servo's limits."""
        return self._limits

    @angle_limit.setter
    def angle_limit(self, limits: tuple[float, float]) -> None:
        self._limits = self._checked_limits(limits[0], limits[1])
        if not self.wheel_mode:
            low, high = self.motor_limits()
            self._store("min_position_limit", low)
            self._store("max_position_limit", high)

    # -- introspection and motion --------------------------------------------------------------

    @property
    def registers(self) -> list[str]:
        """The attribute names this motor offers (they depend on the model)."""
        return list(self._register_names)

    @functools.cached_property
    def _register_names(self) -> tuple[str, ...]:
        names = [
            "id", "name", "model", "orientation", "offset", "angle_limit",
            "present_position", "present_speed", "present_load",
            "present_temperature", "present_voltage",
            "goal_position", "goal_speed", "moving_speed", "compliant", "compliant_behavior",
            "led", "lower_limit", "upper_limit", "goto_behavior", "control_mode", "registers",
            "safe_compliant",
        ]  # fmt: skip
        if self.model.has_torque_limit:
            names += ["torque_limit", "max_torque"]
        if regs.pid_names(self.model) is not None:
            names.append("pid")
        if regs.has_compliance_slopes(self.model):
            names += ["compliance_margin", "compliance_slope"]
        return tuple(names)

    def mark_closed(self) -> None:
        """The robot is closed: later writes raise ``RobotClosedError`` (reads keep the last
        values)."""
        self._closed = True

    def _store(self, name: str, value: SIValue) -> None:
        if self._closed:
            raise RobotClosedError(f"{self.name}: the robot is closed, {name} cannot be written")
        super()._store(name, value)

    def attach_runner(self, runner: GotoRunner) -> None:
        """Use the robot's goto runner (the private one is dropped)."""
        self._runner = runner

    def goto_position(
        self,
        position: float,
        duration: float,
        control: str | None = None,
        wait: bool = False,
    ) -> GotoHandle:
        """Go to ``position`` (degrees, user frame) in ``duration`` seconds.

        Args:
            position: the target, clamped to the angle limits.
            duration: seconds to get there.
            control: ``"minjerk"`` (smooth, on time) or ``"dummy"`` (one goal, constant speed);
                None: ``goto_behavior``.
            wait: block until the motion is over.

        Returns:
            A handle to wait on; a later goto or goal on this motor cancels it.
        """
        handle = self._runner.start({self: position}, duration, control)
        if wait:
            handle.wait()
        return handle
