"""Start-up checks of a robot's motors: presence and model, first state, return delay, limits.

Angle limits: like pypot, the configured limits are written to the servos' EEPROM angle limits
at start-up (only when they differ by more than one step, to spare the EEPROM), so the servo's
own firmware enforces them too. A config's ``angle_limit`` is in the motor frame, as in pypot
(``pypot.robot.config`` writes it to the EEPROM as it is), so the same values land in the
EEPROM as with pypot; the ``Motor`` shows them in the user frame. ``write_angle_limits=False``
leaves the EEPROM alone; goals are clamped in software either way.

EEPROM writes (return delay, angle limits) on a motor whose protocol locks the EEPROM while its
torque is on (protocol 2: XL-320, X series) make a stiff motor compliant for the write and stiff
again after it.
"""

from __future__ import annotations

import contextlib
import logging
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from poppy_core.bus import DxlBus
from poppy_core.bus.results import PingResult
from poppy_core.bus.setup import eeprom_unlocked
from poppy_core.errors import BusError, MotorError, RegisterError
from poppy_core.robot import registers as regs
from poppy_core.robot.motor import Motor
from poppy_core.robot.motor_link import link_of

logger = logging.getLogger(__name__)


@dataclass(frozen=True)
class ReturnDelayIssue:
    """A motor whose return delay is above the wanted one (0 µs unless the config says)."""

    motor: str
    id: int
    delay_us: float
    target_us: float
    port: str = ""
    """The port of the motor's bus (for advice naming the command that fixes it)."""

    def __str__(self) -> str:
        return f"{self.motor} (id {self.id}): {self.delay_us:g} µs"


ReturnDelayConsent = bool | Callable[[list[ReturnDelayIssue]], bool]
"""True/False, or a function shown the issues that returns whether to fix them (a function
that declines says what to do itself: only False logs the advice, a warning)."""


def where(bus: DxlBus) -> str:
    """``/dev/ttyUSB0 at 1000000 bps, protocol 1`` (for messages)."""
    return f"{bus.port} at {bus.baudrate} bps, protocol {bus.protocol}"


STARTUP_PING_RETRIES = 3
# A motor silent through its start-up pings is asked this many times more, patiently
# (``check_presence``), before it counts as missing.
PRESENCE_RETRIES = 1
# Start-up reads and writes go to motors that answered their ping: a reply the OS delivered
# late (an emulator starved on a loaded machine, seen stalling past 20 ms beside four busy
# loops) must not fail the first state or a write the user agreed to. A motor that answers in
# time costs nothing more; one that stopped answering costs at most 4 x 0.1 s per transaction.
STARTUP_RETRIES = 3
STARTUP_REPLY_TIMEOUT_S = 0.1


def _patient(bus: DxlBus) -> contextlib.AbstractContextManager[None]:
    return bus.patient(STARTUP_RETRIES, STARTUP_REPLY_TIMEOUT_S)


def check_presence(bus: DxlBus, controller: str, motors: Sequence[Motor]) -> list[str]:
    """Ping every motor; return one readable problem per missing motor or wrong model.

    Motors that do not answer are marked offline (``motor.online`` is False).
    """
    found = {
        motor.id: _ping(bus, motor.id, max(STARTUP_PING_RETRIES, bus.retries)) for motor in motors
    }
    _ask_the_silent_again(bus, found)
    missing: list[str] = []
    wrong: list[str] = []
    for motor in motors:
        pinged = found[motor.id]
        if pinged is None:
            link_of(motor).mark_offline()
            missing.append(f"{motor.name} (id {motor.id})")
            continue
        if pinged.model is None or pinged.model.name != motor.model.name:
            seen = pinged.model_name or f"model number {pinged.model_number}"
            wrong.append(f"{motor.name} (id {motor.id}) is {seen}, config says {motor.model.name}")
    problems = []
    if missing:
        problems.append(
            f"controller {controller!r}: missing motors {', '.join(missing)} "
            f"(searched {where(bus)})"
        )
    if wrong:
        problems.append(f"controller {controller!r}: wrong model: {', '.join(wrong)}")
    return problems


def _ping(bus: DxlBus, motor_id: int, retries: int) -> PingResult | None:
    try:
        return bus.ping(motor_id, retries=retries)
    except BusError:
        return None


def _ask_the_silent_again(bus: DxlBus, found: dict[int, PingResult | None]) -> None:
    """Ping the motors that did not answer once more, patiently, before they count as missing.

    A robot is refused when one motor is missing, and a reply the OS delivered late (an
    emulator starved on a busy machine: a first ping went unanswered 4 times in a row, 45 ms)
    must not decide it. Each silent motor is pinged again (``PRESENCE_RETRIES`` retries),
    waiting ``STARTUP_REPLY_TIMEOUT_S`` for each reply. When no motor answered at all (most
    likely an empty bus, or one at another rate), the first is asked, and the others only if
    it answers: a whole robot absent costs 0.2 s more, not 0.2 s a motor.
    """
    silent = [motor_id for motor_id, pinged in found.items() if pinged is None]
    if not silent:
        return
    with bus.patient(PRESENCE_RETRIES, STARTUP_REPLY_TIMEOUT_S):
        if len(silent) == len(found):
            first = silent.pop(0)
            found[first] = _ping(bus, first, PRESENCE_RETRIES)
            if found[first] is None:
                return
        for motor_id in silent:
            found[motor_id] = _ping(bus, motor_id, PRESENCE_RETRIES)
    answered_late = [motor_id for motor_id in silent if found[motor_id] is not None]
    if answered_late:
        logger.info("%s: motors %s answered only when asked patiently", bus.port, answered_late)


def load_state(bus: DxlBus, motors: Sequence[Motor]) -> None:
    """Read each online motor's control table once and fill its cache (one read per motor)."""
    with _patient(bus):
        for motor in motors:
            if not motor.online:
                continue
            data = bus.read(motor.id, 0, motor.model.table_size)
            link_of(motor).update(regs.decode_table(motor.model, data))


def return_delay_issues(
    motors: Sequence[Motor], targets_us: dict[str, float], port: str = ""
) -> list[ReturnDelayIssue]:
    """Motors (on the bus at ``port``) whose return delay (read by ``load_state``) is above its
    target."""
    issues = []
    for motor in motors:
        if not motor.online:
            continue
        delay = link_of(motor).number("return_delay_time")
        target = targets_us.get(motor.name, 0.0)
        if delay > target:
            issues.append(ReturnDelayIssue(motor.name, motor.id, delay, target, port))
    return issues


def fix_return_delays(
    bus: DxlBus,
    motors: Sequence[Motor],
    issues: list[ReturnDelayIssue],
    consent: ReturnDelayConsent,
) -> list[ReturnDelayIssue]:
    """Report return delays above target and, with consent, write the targets.

    The return delay is in the EEPROM, which protocol 2 servos lock while their torque is on:
    a stiff motor is made compliant for the write and stiff again after it.

    Returns:
        The issues left unfixed.
    """
    if not issues:
        return []
    agreed = consent(issues) if callable(consent) else consent
    if not agreed:
        # a consent function was shown the issues and told its user what to do
        log = logger.info if callable(consent) else logger.warning
        log(
            "return delay above 0 slows every transaction on %s: %s "
            "(fix_return_delay=True sets it to 0 at start-up)",
            bus.port,
            ", ".join(map(str, issues)),
        )
        return issues
    by_name = {m.name: m for m in motors}
    left = []
    for issue in issues:
        motor = by_name[issue.motor]
        try:
            with _patient(bus), eeprom_unlocked(bus, motor.id, motor.model):
                bus.write_register(motor.id, motor.model, "return_delay_time", issue.target_us)
        except (BusError, MotorError, RegisterError) as exc:
            logger.warning("%s: could not set the return delay: %s", issue.motor, exc)
            left.append(issue)
            continue
        link_of(motor).update({"return_delay_time": issue.target_us})
        logger.info("%s: return delay set to %g µs", issue.motor, issue.target_us)
    return left


def write_angle_limits(bus: DxlBus, motors: Sequence[Motor]) -> None:
    """Write each motor's limits (motor frame) to its EEPROM when they differ (see module doc)."""
    for motor in motors:
        if not motor.online or motor.wheel_mode:
            continue
        model = motor.model
        step = model.position_range_deg / model.resolution
        wanted = motor.motor_limits()
        names = ("min_position_limit", "max_position_limit")
        present = (link_of(motor).number(names[0]), link_of(motor).number(names[1]))
        if all(abs(w - p) <= step for w, p in zip(wanted, present, strict=True)):
            continue
        try:
            # a stiff motor stays stiff after
            with _patient(bus), eeprom_unlocked(bus, motor.id, model):
                for name, value in zip(names, wanted, strict=True):
                    bus.write_register(motor.id, model, name, value)
        except (BusError, MotorError) as exc:
            logger.warning(
                "%s: could not write its angle limits %s: %s",
                motor.name,
                wanted,
                exc,
            )
            continue
        link_of(motor).update(dict(zip(names, wanted, strict=True)))
        logger.info(
            "%s: EEPROM angle limits %s -> %s (motor frame)",
            motor.name,
            tuple(round(p, 1) for p in present),
            tuple(round(w, 1) for w in wanted),
        )
