"""Guided motor setup from a kit: one motor at a time on the bus, given its profile's settings.

Every new motor of a kit answers at its factory ID (1 for an XL-320) and rate: they cannot
share a bus until each has its own ID. The flow asks for one motor at a time ("plug only m3
(XL-320) on the bus"), finds the single motor answering at any ID, rate and protocol, and
gives it its profile's ID, return delay, angle limits (motor frame) and baud rate, with the
never-strand steps of ``poppy_core.bus.setup`` (each change verified; the rate last, the bus
following it; a motor lost on a rate change is looked for and said where it is). Then every
setting is read back at the profile's rate. A motor already right is left as it is.

The CLI (`poppy setup motors`) and the TUI's setup screen both drive :class:`GuidedSetup`.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field

from poppy_core.bus.dxlbus import DxlBus
from poppy_core.bus.groupread import count_answers
from poppy_core.bus.results import FoundMotor
from poppy_core.bus.scan import PROTOCOLS, scan
from poppy_core.bus.setup_reset import reset_motor
from poppy_core.bus.timing import reply_floor_s
from poppy_core.errors import PoppyError, SetupError
from poppy_core.models import ServoModel, model_by_name, standard_baudrates
from poppy_core.protocol import protocol_for
from poppy_core.robot.config import RobotConfig

logger = logging.getLogger(__name__)

Progress = Callable[[str], None]
DEFAULT_RETURN_DELAY_US = 0.0
"""The return delay a Poppy robot's motors get unless the profile says another (µs)."""
REPLY_TIMEOUT_S = 0.1
"""The shortest wait for a reply during setup (a silent motor costs no more than that)."""


@dataclass(frozen=True)
class MotorTarget:
    """What one motor of the profile must be: its name, model, ID, rate, delay and limits."""

    name: str
    model: str
    id: int
    baudrate: int
    protocol: int
    return_delay_us: float
    angle_limits: tuple[float, float]

    @property
    def servo(self) -> ServoModel:
        """The servo model."""
        return model_by_name(self.model)

    @property
    def prompt(self) -> str:
        """What the person is asked to do before this motor is set up."""
        return f"plug only {self.name} ({self.model}) on the bus and press Enter"


def motor_targets(config: RobotConfig, only: Iterable[str] | None = None) -> list[MotorTarget]:
    """The profile's motors in order (controller by controller), each with what it must be.

    Args:
        config: the robot's config (a profile).
        only: motor names to keep (None: every motor), in the profile's order.

    Raises:
        SetupError: a name in ``only`` that the profile does not have.
    """
    targets = []
    for controller_name, controller in config.controllers.items():
        for name in config.motors_of_controller(controller_name):
            entry = config.motors[name]
            delay = entry.return_delay_time
            servo = model_by_name(entry.type)
            targets.append(
                MotorTarget(
                    name=name,
                    model=servo.name,
                    id=entry.id,
                    baudrate=controller.baudrate,
                    protocol=controller.protocol,
                    return_delay_us=DEFAULT_RETURN_DELAY_US if delay is None else float(delay),
                    angle_limits=_held_limits(servo, entry.angle_limit),
                )
            )
    if only is None:
        return targets
    wanted = list(only)
    unknown = [n for n in wanted if n not in {t.name for t in targets}]
    if unknown:
        known = ", ".join(t.name for t in targets)
        raise SetupError(f"no motor {', '.join(unknown)} in this profile (motors: {known})")
    return [t for t in targets if t.name in wanted]


@dataclass
class StepOutcome:
    """What setting up one motor did.

    Attributes:
        motor: the profile's name of the motor.
        found: where and what the motor was when found.
        changes: register -> (before, after) of what was written.
        skipped: the motor was already right: nothing written.
        next_motor: the name of the motor to plug next, None after the last.
    """

    motor: str
    found: FoundMotor
    changes: dict[str, tuple[object, object]] = field(default_factory=dict)
    skipped: bool = False
    next_motor: str | None = None

    def summary(self) -> str:
        """One line saying what the step did and which motor is next."""
        found = self.found
        if self.skipped:
            head = (
                f"{self.motor}: already right (ID {found.id} at {found.baudrate} bps), left as is"
            )
        else:
            changed = ", ".join(self.changes) or "nothing"
            head = f"{self.motor}: found as ID {found.id} at {found.baudrate} bps; set {changed}"
        tail = f"next: {self.next_motor}" if self.next_motor else "all motors done"
        return f"{head} — {tail}"

    def as_dict(self) -> dict[str, object]:
        """The outcome as JSON-ready data (the shape of `poppy setup motors --json`)."""
        return {
            "motor": self.motor,
            "found": {
                "id": self.found.id,
                "baud": self.found.baudrate,
                "protocol": self.found.protocol,
                "model": self.found.model,
            },
            "changes": {k: [v[0], v[1]] for k, v in self.changes.items()},
            "skipped": self.skipped,
            "next": self.next_motor,
        }


def _held_limits(model: ServoModel, limits: tuple[float, float]) -> tuple[float, float]:
    """The profile's limits (motor frame) kept inside what the limit registers can hold (an
    XL-320's 150° is 149.7°), as the robot's start-up writes them (``Motor.motor_limits``)."""
    register = model.register("min_position_limit")
    ends = sorted(float(register.to_si(r)) for r in (register.min_raw, register.max_raw))
    return max(float(limits[0]), ends[0]), min(float(limits[1]), ends[1])


def _where(found: FoundMotor) -> str:
    return f"ID {found.id} at {found.baudrate} bps, protocol {found.protocol}"


def _step_deg(model: ServoModel) -> float:
    return model.position_range_deg / model.resolution


def read_settings(bus: DxlBus, motor_id: int, model: ServoModel) -> dict[str, float]:
    """The settings the setup gives, as the motor holds them: return delay (µs), limits (°)."""
    names = ("return_delay_time", "min_position_limit", "max_position_limit")
    return {name: float(bus.read_register(motor_id, model, name)) for name in names}


def settings_match(settings: dict[str, float], target: MotorTarget, model: ServoModel) -> bool:
    """Whether the read ``settings`` are the target's (limits within one position step)."""
    step = _step_deg(model)
    low, high = target.angle_limits
    return (
        abs(settings["return_delay_time"] - target.return_delay_us) < 1.0
        and abs(settings["min_position_limit"] - low) <= step
        and abs(settings["max_position_limit"] - high) <= step
    )


class GuidedSetup:
    """Set the motors of a profile up one at a time on ``port`` (see the module docstring).

    Args:
        config: the robot's profile.
        port: the serial port (device path or URL) the motors are plugged on, one at a time.
        only: motor names to set up (None: all, in the profile's order).
    """

    def __init__(self, config: RobotConfig, port: str, only: Iterable[str] | None = None) -> None:
        self.port = port
        self.targets = motor_targets(config, only)

    def _bus(self, rate: int, protocol: int) -> DxlBus:
        """A bus that waits long for replies: setup is not timed, and a busy machine (or a
        slow adapter, learned from its late replies) answers late."""
        floor = max(REPLY_TIMEOUT_S, reply_floor_s())
        bus = DxlBus(self.port, rate, protocol, retries=2, min_timeout_s=floor)
        bus.adaptive_latency = True
        return bus

    def next_after(self, target: MotorTarget) -> str | None:
        """The name of the motor after ``target``, None after the last."""
        names = [t.name for t in self.targets]
        index = names.index(target.name)
        return names[index + 1] if index + 1 < len(names) else None

    def find_single(self, target: MotorTarget, progress: Progress | None = None) -> FoundMotor:
        """The one motor on the bus, found at any ID and rate in the target's protocol (and,
        if none answers there, in the other protocol, to name a wrong model; in protocol 1 from
        the profile's rate, rate by rate until one answers, as ``_scan_protocol``).

        Raises:
            SetupError: no motor, several motors, or a motor of another model.
        """
        say(progress, f"looking for {target.name} on {self.port}")
        found = self._scan_protocol(target)
        if not found:
            say(progress, f"nothing in protocol {target.protocol}: trying the other")
            for other in (p for p in PROTOCOLS if p != target.protocol):
                rates = sorted(standard_baudrates(other), key=lambda r: r != target.baudrate)
                found = self._scan_rates(other, rates)
                if found:
                    break
        if not found:
            raise SetupError(
                f"nothing answers on {self.port} (every ID and standard rate, protocols 1 and "
                f"2): is {target.name} plugged and powered?"
            )
        if len(found) > 1:
            listed = "; ".join(f"{m.model or m.model_number} at {_where(m)}" for m in found)
            raise SetupError(
                f"{len(found)} motors answer on {self.port} ({listed}): unplug all but "
                f"{target.name}"
            )
        motor = found[0]
        if protocol_for(motor.protocol).has_broadcast_ping:  # motors sharing an ID all answer
            with self._bus(motor.baudrate, motor.protocol) as bus:
                sharing = count_answers(bus)[motor.id]
            if sharing > 1:
                raise SetupError(
                    f"{sharing} motors answer on {self.port} as {_where(motor)}: unplug all "
                    f"but {target.name}"
                )
        if motor.model != target.model:
            what = motor.model or f"a motor of unknown model number {motor.model_number}"
            article = "" if motor.model is None else _article(motor.model)
            raise SetupError(
                f"found {article}{what} at {_where(motor)}, {target.name} is "
                f"{_article(target.model)}{target.model}: plug {target.name} instead"
            )
        return motor

    def _scan_protocol(self, target: MotorTarget) -> list[FoundMotor]:
        """The motors answering in the target's protocol: the profile's rate first, then the
        model's factory rate, then the others.

        With a broadcast ping (protocol 2) every rate is scanned (a rate costs a few
        milliseconds). Without (protocol 1: each of the 254 IDs pinged, a second or more a
        rate), the search stops after the first rate where a motor answers: the profile's
        rate is always searched, so a motor there, which the new settings could collide with,
        is seen.
        """
        factory = target.servo.register("baudrate").default
        factory_bps = None if factory is None else target.servo.baudrate_bps(factory)
        rates = list(standard_baudrates(target.protocol))
        rates.sort(key=lambda r: (r != target.baudrate, r != factory_bps))
        return self._scan_rates(target.protocol, rates)

    def _scan_rates(self, protocol: int, rates: list[int]) -> list[FoundMotor]:
        """The motors answering in ``protocol`` at ``rates``: all of them with a broadcast ping;
        without, rate by rate until one answers (patient at the first rate only)."""
        if protocol_for(protocol).has_broadcast_ping:
            return scan(self.port, rates, [protocol])
        for index, rate in enumerate(rates):
            # patient at the first rate only: each empty rate would pay the patient look
            found = scan(self.port, [rate], [protocol], patient=index == 0)
            if found:
                return found
        return []

    def set_up(self, target: MotorTarget, progress: Progress | None = None) -> StepOutcome:
        """Find the one motor on the bus and give it ``target``'s settings, verified.

        Raises:
            SetupError: see :meth:`find_single`; a step that did not hold (the message says
                where the motor is and how to go on).
        """
        found = self.find_single(target, progress)
        model = target.servo
        outcome = StepOutcome(target.name, found, next_motor=self.next_after(target))
        with self._bus(found.baudrate, found.protocol) as bus:
            right_place = (found.id, found.baudrate) == (target.id, target.baudrate)
            if right_place and settings_match(read_settings(bus, found.id, model), target, model):
                outcome.skipped = True
                say(progress, f"{target.name} is already set up (ID {target.id}): left as it is")
                return outcome
            try:
                result = reset_motor(
                    bus,
                    found.id,
                    model,
                    target_id=target.id,
                    baudrate=target.baudrate,
                    angle_limits=target.angle_limits,
                    return_delay_us=target.return_delay_us,
                    progress=progress,
                )
            except PoppyError as exc:
                raise SetupError(
                    f"{target.name}: {exc}. Nothing else is on the bus, so running the setup "
                    f"again for {target.name} finds it at any ID and rate"
                ) from exc
            outcome.changes = dict(result.changes)
        self.verify(target)
        say(progress, f"{target.name} is ready: ID {target.id} at {target.baudrate} bps")
        return outcome

    def verify(self, target: MotorTarget) -> None:
        """Read every setting back on a fresh bus at the profile's rate and protocol.

        Raises:
            SetupError: the motor does not answer there, or a setting does not read back.
        """
        model = target.servo
        with self._bus(target.baudrate, target.protocol) as bus:
            pinged = bus.ping(target.id)
            if pinged is None or pinged.model is None or pinged.model.name != model.name:
                raise SetupError(
                    f"{target.name} does not answer as ID {target.id} at {target.baudrate} bps "
                    "after its setup: run the setup again for it"
                )
            settings = read_settings(bus, target.id, model)
        if not settings_match(settings, target, model):
            raise SetupError(f"{target.name}: its settings read back as {settings}")


def _article(name: str) -> str:
    """``"an "`` before a name said with a vowel sound (MX, AX, XL: "em", "ay", "ex")."""
    return "an " if name[:1].upper() in "AEFHILMNORSX" else "a "


def say(progress: Progress | None, message: str) -> None:
    logger.info(message)
    if progress is not None:
        progress(message)
