"""``Motor``: one servo in SI units, with orientation, offset and limits, cached by the sync loops.

Frames (``poppy_core.robot.frames``): the *motor frame* is the servo's own (``poppy_core.models``
degrees, 0° mid-range); the *user frame* is what a robot script sees. With ``s = +1`` (direct)
or ``-1`` (indirect)::

    user = s * motor - offset          motor = s * (user + offset)

Speeds and loads flip their sign with the orientation. A ``Motor`` speaks the user frame,
angle limits included; a config's ``angle_limit`` is in the motor frame, as in pypot (what the
servo's EEPROM holds), and ``from_config`` converts it.

Nothing here touches the bus: reads return the values the sync loops last read, writes store the
value and mark it for the next write cycle. That side (register cache, pending writes, online
state) is the motor's ``MotorLink`` (``poppy_core.robot.motor_link``), which only the robot's
internals reach (``link_of``): a ``Motor``'s public names are the user's API. pypot's other
names and the model-specific registers are in ``poppy_core.robot.motor_pypot``; compliance
(``compliant``, ``compliant_behavior``, safe compliance) in ``poppy_core.robot.motor_compliance``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Literal

from poppy_core import checks
from poppy_core.errors import RegisterError
from poppy_core.models import ServoModel
from poppy_core.robot import frames
from poppy_core.robot import registers as regs
from poppy_core.robot.goto import GotoHandle, GotoRunner
from poppy_core.robot.motor_compliance import CompliantBehavior, MotorCompliance
from poppy_core.robot.motor_link import MotorLink
from poppy_core.robot.motor_pypot import PypotMotorMixin
from poppy_core.trajectory import clamp_goal

if TYPE_CHECKING:
    from poppy_core.robot.config import MotorConfig

FULL_TORQUE_PCT = 100.0
# poppy's gotos are smooth by default (pypot's motors default to 'dummy'; its Torso and Humanoid
# set 'minjerk'): the pypot creature classes set their creature's control.
DEFAULT_GOTO_BEHAVIOR = "minjerk"


class Motor(PypotMotorMixin, MotorCompliance):
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
                register="orientation",
                motor=name,
            )
        self.name = name
        self.model = model
        self.id = id
        self.orientation: Literal["direct", "indirect"] = orientation
        self.offset = float(offset)
        self.wheel_mode = wheel_mode
        self._behavior: CompliantBehavior = "dummy"
        self._goto_behavior = DEFAULT_GOTO_BEHAVIOR
        self._goal_speed: float | None = None
        self.ideal_plant = False
        """True for a servo of an ideal simulation (``sim=True``, ``simulator='dummy'``): its
        ``present_position`` reads the goal once reached (see there)."""
        position = model.register("present_position")
        self._half_step = abs(float(position.to_si(1)) - float(position.to_si(0))) / 2 + 1e-9
        self._link = MotorLink(
            name,
            model,
            runner if runner is not None else GotoRunner(name=f"goto {name}"),
            on_position=self._apply_safe_compliance,
            set_goal=self._set_goal,
        )
        # The motor-frame range a position limit register can hold (AX -150..149.7°).
        register = model.register("min_position_limit")
        ends = sorted(float(register.to_si(r)) for r in (register.min_raw, register.max_raw))
        self._range = (ends[0], ends[1])
        low, high = angle_limit if angle_limit is not None else self._user_range()
        self._limits: tuple[float, float] = self._checked_limits(low, high)

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
                register="angle_limit",
                motor=self.name,
            )
        return float(low), float(high)

    # -- present values (read-only) --------------------------------------------------------------

    @property
    def present_position(self) -> float:
        """Position in degrees (user frame), as last read.

        On an ideal virtual servo (``ideal_plant``) that reached its goal (within half a step of
        the position register), the goal itself, as pypot's dummy robot gave it: the register's
        steps would read 89.94° for a goal of 90° on an AX-12A, as a real servo does.
        """
        present = self.to_user(self._link.number("present_position"))
        if self.ideal_plant and not self.wheel_mode:
            goal = self.goal_position
            if abs(present - goal) <= self._half_step:
                return goal
        return present

    @property
    def present_speed(self) -> float:
        """Speed in deg/s (user frame sign), as last read."""
        return self._sign * self._link.number("present_speed")

    @property
    def present_load(self) -> float:
        """Load in % of the maximum (user frame sign; mA on XM430/XL330), as last read."""
        return self._sign * self._link.number("present_load")

    @property
    def present_temperature(self) -> float:
        """Temperature in °C, as last read (read at a low rate)."""
        return self._link.number("present_temperature")

    @property
    def present_voltage(self) -> float:
        """Supply voltage in V, as last read (read at a low rate)."""
        return self._link.number("present_voltage")

    temperature = present_temperature
    voltage = present_voltage
    load = present_load

    @property
    def online(self) -> bool:
        """False once the sync loop found the motor silent: its values are then stale (it is
        pinged until it answers again)."""
        return self._link.online

    @property
    def errors(self) -> int:
        """Failed reads so far."""
        return self._link.errors

    # -- goals -------------------------------------------------------------------------------

    @property
    def goal_position(self) -> float:
        """Goal in degrees (user frame); set values are clamped to ``angle_limit``."""
        return self.to_user(self._link.number("goal_position"))

    @goal_position.setter
    def goal_position(self, value: float) -> None:
        target = checks.number(value, f"{self.name}.goal_position")  # huge: refused, not clamped
        self._link.runner.cancel(self)
        self._set_goal(target)

    def _set_goal(self, user_deg: float) -> None:
        """Set the goal position without cancelling a running goto (the goto runner's way, through
        ``MotorLink.set_goal``)."""
        target = clamp_goal(float(user_deg), None if self.wheel_mode else self._limits)
        motor_deg = self.to_motor(target)
        bottom, top = self._range if self.wheel_mode else self.motor_limits()
        self._link.store("goal_position", min(max(motor_deg, bottom), top))
        self._goal_speed = None

    @property
    def moving_speed(self) -> float:
        """Speed limit toward the goal in deg/s (0 = the servo's full speed).

        A speed beyond the register's top is capped to it, as pypot and the servo do; NaN, an
        infinity or a non-number is refused (``ArgumentError``), a negative one too.
        """
        return abs(self._link.number("moving_speed"))

    @moving_speed.setter
    def moving_speed(self, value: float) -> None:
        speed = regs.finite(value, f"{self.name}.moving_speed")
        if speed < 0:
            raise RegisterError(
                f"{self.name}: moving_speed is a magnitude (>= 0), got {value}",
                register="moving_speed",
                motor=self.name,
            )
        register = self.model.register("moving_speed")
        self._link.store("moving_speed", regs.capped(register, speed, "moving_speed"))

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
        speed = regs.finite(value, f"{self.name}.goal_speed")
        self._link.runner.cancel(self)
        register = self.model.register("moving_speed")
        smallest = abs(float(register.to_si(1)))  # 0 means full speed: never send it
        if abs(speed) < smallest / 2:
            self._set_goal(self.present_position)
            self._goal_speed = 0.0
            return
        magnitude = min(max(abs(speed), smallest), self.model.no_load_speed_dps)
        low, high = self._limits if not self.wheel_mode else self._user_range()
        self.moving_speed = magnitude
        self._set_goal(high if speed > 0 else low)
        self._goal_speed = magnitude if speed > 0 else -magnitude

    @property
    def torque_limit(self) -> float:
        """Torque limit in % (RAM); always 100 on models without one (X-series)."""
        if not self.model.has_torque_limit:
            return FULL_TORQUE_PCT
        return self._link.number("torque_limit")

    @torque_limit.setter
    def torque_limit(self, value: float) -> None:
        if not self.model.has_torque_limit:
            raise RegisterError(
                f"{self.name}: {self.model.name} has no torque limit register",
                register="torque_limit",
                motor=self.name,
            )
        self._link.store("torque_limit", regs.finite(value, f"{self.name}.torque_limit"))

    # -- limits ------------------------------------------------------------------------------

    @property
    def angle_limit(self) -> tuple[float, float]:
        """(min, max) in degrees, user frame; setting it also updates the servo's limits."""
        return self._limits

    @angle_limit.setter
    def angle_limit(self, limits: tuple[float, float]) -> None:
        self._limits = self._checked_limits(limits[0], limits[1])
        if not self.wheel_mode:
            low, high = self.motor_limits()
            self._link.store("min_position_limit", low)
            self._link.store("max_position_limit", high)

    # -- motion --------------------------------------------------------------------------------

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
        handle = self._link.runner.start({self: position}, duration, control)
        if wait:
            handle.wait()
        return handle
