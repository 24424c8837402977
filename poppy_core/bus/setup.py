"""Motor setup that never strands a motor: every change is verified, and a lost motor is found.

* EEPROM writes first turn torque off on protocol 2 models (X series and XL-320 lock their
  EEPROM while torque is on; e-manual "Torque Enable").
* A write that changes the ID or the baud rate may be answered from the new ID or at the new
  rate (or not at all): its reply is not relied upon; the motor is pinged at the new setting.
* ``factory_reset`` (in ``setup_reset``, which builds on this module) on protocol 1 resets
  everything (ID and baud rate included): the motor is then looked for at the model's factory ID
  and rate and, as asked, its ID and baud rate are put back. Before resetting, the factory ID
  must be free at the factory rate, else two motors would end up sharing it.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager

from poppy_core.bus.dxlbus import DxlBus
from poppy_core.bus.results import PingResult, SetupResult
from poppy_core.errors import CommunicationError, SetupError
from poppy_core.models import ServoModel, SIValue, standard_baudrates
from poppy_core.models.degrees import fmt_deg, tick_deg
from poppy_core.protocol import protocol_for

logger = logging.getLogger(__name__)

Progress = Callable[[str], None]

# e-manual (Protocol 2.0 Factory Reset): 0xFF all, 0x01 all but ID, 0x02 all but ID and baud.
RESET_ALL, RESET_KEEP_ID, RESET_KEEP_ID_BAUDRATE = 0xFF, 0x01, 0x02
# How long a motor may take to answer again after a reboot, reset or rate change.
ANSWER_TIMEOUT_S = 1.0
_POLL_S = 0.005


def say(progress: Progress | None, message: str) -> None:
    logger.info(message)
    if progress is not None:
        progress(message)


def where(bus: DxlBus) -> str:
    return f"{bus.port} at {bus.baudrate} bps, protocol {bus.protocol}"


def identify(bus: DxlBus, motor_id: int) -> tuple[PingResult, ServoModel]:
    """Ping ``motor_id`` and return its ping result and model.

    Raises:
        SetupError: no answer, or a model number poppy does not know.
    """
    found = bus.ping(motor_id)
    if found is None:
        raise SetupError(f"motor {motor_id} does not answer on {where(bus)}")
    if found.model is None:
        raise SetupError(
            f"motor {motor_id} on {bus.port} has unknown model number {found.model_number}: "
            "poppy cannot set it up"
        )
    return found, found.model


def wait_for_answer(bus: DxlBus, motor_id: int, timeout_s: float = ANSWER_TIMEOUT_S) -> bool:
    """Ping ``motor_id`` until it answers or ``timeout_s`` passes."""
    end = time.monotonic() + timeout_s
    while True:
        if bus.ping(motor_id, retries=0) is not None:
            return True
        if time.monotonic() >= end:
            return False
        time.sleep(_POLL_S)


def unlock_eeprom(bus: DxlBus, motor_id: int, model: ServoModel) -> None:
    if protocol_for(model.protocol).torque_locks_eeprom:
        bus.write_register(motor_id, model, "torque_enable", False)


def _write_unanswered(bus: DxlBus, motor_id: int, model: ServoModel, name: str, value: int) -> None:
    """Write the ID or the baud rate, the EEPROM unlocked: the motor may answer at its new ID or
    rate, or not at all (some firmwares), so a missing acknowledgement is only logged."""
    unlock_eeprom(bus, motor_id, model)
    try:
        bus.write_register(motor_id, model, name, value)
    except CommunicationError as exc:
        logger.debug("%s write not acknowledged (expected from some firmwares): %s", name, exc)


@contextmanager
def eeprom_unlocked(bus: DxlBus, motor_id: int, model: ServoModel) -> Iterator[None]:
    """EEPROM writes allowed in the block: a stiff motor whose protocol locks its EEPROM while
    the torque is on is made compliant for the block and stiff again after it (it holds its
    goal again), so a running robot is left as it was found."""
    if not protocol_for(model.protocol).torque_locks_eeprom:
        yield
        return
    stiff = bool(bus.read_register(motor_id, model, "torque_enable"))
    if stiff:
        bus.write_register(motor_id, model, "torque_enable", False)
    try:
        yield
    finally:
        if stiff:
            bus.write_register(motor_id, model, "torque_enable", True)


def _write_verified(
    bus: DxlBus, motor_id: int, model: ServoModel, name: str, value: SIValue
) -> tuple[SIValue, SIValue]:
    """Write register ``name``, read it back, and return (old, new) SI values (a stiff motor
    whose EEPROM locks is compliant for an EEPROM write and stiff again after it)."""
    register = model.register(name)
    wanted = register.from_si(value)
    old = bus.read_register(motor_id, model, name)
    if register.memory == "EEPROM":
        with eeprom_unlocked(bus, motor_id, model):
            bus.write_register(motor_id, model, name, value)
    else:
        bus.write_register(motor_id, model, name, value)
    raw = register.decode(bus.read(motor_id, register.address, register.size))
    if raw != wanted:
        raise SetupError(
            f"motor {motor_id} on {bus.port}: {name} reads {register.to_si(raw)} after writing "
            f"{value}"
        )
    return old, register.to_si(raw)


def new_result(bus: DxlBus, operation: str, motor_id: int) -> SetupResult:
    return SetupResult(operation, bus.port, motor_id, bus.baudrate, bus.protocol)


def change_id(
    bus: DxlBus, old_id: int, new_id: int, *, progress: Progress | None = None
) -> SetupResult:
    """Give motor ``old_id`` the ID ``new_id``, verified.

    Raises:
        SetupError: the motor does not answer, ``new_id`` is taken, or the change did not hold.
        RegisterError: ``new_id`` is outside the model's ID range.
    """
    _, model = identify(bus, old_id)
    result = new_result(bus, "change_id", old_id)
    if new_id == old_id:
        result.verified = True
        return result
    model.register("id").from_si(new_id)
    if bus.ping(new_id) is not None:
        raise SetupError(f"ID {new_id} is already taken on {bus.port}")
    say(progress, f"motor {old_id}: setting ID {new_id}")
    _write_unanswered(bus, old_id, model, "id", new_id)
    if not wait_for_answer(bus, new_id):
        still_old = bus.ping(old_id) is not None
        hint = f"it still answers as {old_id}" if still_old else "run `poppy scan` to find it"
        raise SetupError(f"motor {old_id} does not answer as {new_id} on {bus.port}: {hint}")
    if bus.ping(old_id, retries=0) is not None:
        raise SetupError(f"both IDs {old_id} and {new_id} answer on {bus.port}: check the wiring")
    result.motor_id = new_id
    result.changes["id"] = (old_id, new_id)
    result.verified = True
    say(progress, f"motor {old_id} is now motor {new_id}")
    return result


# How long ``locate`` listens at each rate for a reply still on its way. It runs where a motor
# was just lost (a baud rate change, a reset), so it can afford to wait for the slowest adapters
# (an FTDI latency timer at 16 ms or more, USB hubs) rather than the scan's short settle, which
# caught a 30 ms adapter's reply only with a millisecond to spare.
LOCATE_SETTLE_S = 0.05


def locate(bus: DxlBus, motor_id: int, rates: list[int] | None = None) -> int | None:
    """Search the standard baud rates for ``motor_id``; leave the bus at the rate found.

    Each rate is left quiet a moment before the next, and a motor that answered is asked
    again, so a slow adapter's late reply is not taken for the motor at the next rate.

    Returns:
        The rate where it answers, None when nowhere (the bus's rate is then restored).
    """
    from poppy_core.bus.settle import answers, settle

    original, adaptive = bus.baudrate, bus.adaptive_latency
    bus.adaptive_latency = True  # a slow adapter is learned from its late replies
    try:
        previous: int | None = None
        for rate in rates if rates is not None else standard_baudrates(bus.protocol):
            bus.baudrate = rate
            # Heard now or late (settle), then confirmed on a settled line (see bus.scan); heard
            # but not confirmed: a late reply from the rate before, looked at again.
            heard = answers(bus, motor_id)
            if motor_id in settle(bus, LOCATE_SETTLE_S) or heard:
                if answers(bus, motor_id):
                    return rate
                if previous is not None:
                    bus.baudrate = previous
                    settle(bus, LOCATE_SETTLE_S)
                    if answers(bus, motor_id):
                        return previous
            previous = rate
        bus.baudrate = original
        return None
    finally:
        bus.adaptive_latency = adaptive


def change_baudrate(
    bus: DxlBus, motor_id: int, baudrate: int, *, progress: Progress | None = None
) -> SetupResult:
    """Set the motor's baud rate, switch the bus to it and check the motor answers there.

    On success the bus stays at ``baudrate``. When the motor does not answer at the new rate,
    the standard rates are searched and ``SetupError`` says where it is (the bus is left there).

    Raises:
        SetupError: the motor does not answer before, or cannot be found at the new rate.
        RegisterError: the model has no such baud rate.
    """
    _, model = identify(bus, motor_id)
    old = bus.baudrate
    result = new_result(bus, "change_baudrate", motor_id)
    model.baudrate_code(baudrate)
    if baudrate != old:
        say(progress, f"motor {motor_id}: setting {baudrate} bps")
        _write_unanswered(bus, motor_id, model, "baudrate", baudrate)
        bus.baudrate = baudrate
        if not wait_for_answer(bus, motor_id):
            found = locate(bus, motor_id)
            where = f"it answers at {found} bps" if found else "it answers at no standard rate"
            raise SetupError(
                f"motor {motor_id} does not answer at {baudrate} bps on {bus.port} after the "
                f"change: {where}"
            )
        result.changes["baudrate"] = (old, baudrate)
    result.baudrate = bus.baudrate
    result.verified = True
    return result


def set_return_delay(
    bus: DxlBus, motor_id: int, delay_us: float, *, progress: Progress | None = None
) -> SetupResult:
    """Set the return delay time (µs; poppy uses 0), verified by reading it back."""
    _, model = identify(bus, motor_id)
    model.register("return_delay_time").from_si(delay_us)  # out of range: refused before a word
    say(progress, f"motor {motor_id}: return delay {delay_us} µs")
    result = new_result(bus, "set_return_delay", motor_id)
    result.changes["return_delay_time"] = _write_verified(
        bus, motor_id, model, "return_delay_time", delay_us
    )
    result.verified = True
    return result


def set_angle_limits(
    bus: DxlBus,
    motor_id: int,
    min_deg: float,
    max_deg: float,
    *,
    progress: Progress | None = None,
) -> SetupResult:
    """Set the angle (position) limits in degrees, verified by reading them back.

    Raises:
        SetupError: ``min_deg >= max_deg`` or the limits did not hold.
        RegisterError: a limit outside the model's range.
    """
    if min_deg >= max_deg:
        raise SetupError(f"angle limits need min < max (got {min_deg:g}° and {max_deg:g}°)")
    _, model = identify(bus, motor_id)
    for name, value in (("min_position_limit", min_deg), ("max_position_limit", max_deg)):
        model.register(name).from_si(value)  # out of range: refused before a word
    step = tick_deg(model)
    say(
        progress,
        f"motor {motor_id}: angle limits {fmt_deg(min_deg, step)} .. {fmt_deg(max_deg, step)}",
    )
    result = new_result(bus, "set_angle_limits", motor_id)
    for name, value in (("min_position_limit", min_deg), ("max_position_limit", max_deg)):
        result.changes[name] = _write_verified(bus, motor_id, model, name, value)
    result.verified = True
    return result


def reboot(
    bus: DxlBus,
    motor_id: int,
    *,
    timeout_s: float = ANSWER_TIMEOUT_S,
    progress: Progress | None = None,
) -> SetupResult:
    """Reboot the motor (protocol 2) and wait until it answers again.

    Raises:
        SetupError: protocol 1 (no reboot instruction), or no answer after ``timeout_s``.
    """
    if not bus.proto.has_reboot:
        raise SetupError("reboot exists only in protocol 2: power-cycle the motor instead")
    identify(bus, motor_id)
    say(progress, f"motor {motor_id}: rebooting")
    start = time.monotonic()
    bus.reboot(motor_id)
    if not wait_for_answer(bus, motor_id, timeout_s):
        raise SetupError(f"motor {motor_id} did not answer within {timeout_s} s after a reboot")
    result = new_result(bus, "reboot", motor_id)
    result.notes.append(f"answered again after {time.monotonic() - start:.3f} s")
    result.verified = True
    return result


__all__ = [
    "ANSWER_TIMEOUT_S",
    "change_baudrate",
    "change_id",
    "eeprom_unlocked",
    "identify",
    "locate",
    "reboot",
    "set_angle_limits",
    "set_return_delay",
    "wait_for_answer",
]
