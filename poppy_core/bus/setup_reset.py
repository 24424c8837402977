"""Whole-motor setup: factory reset without losing the motor, and poppy's ``reset_motor``."""

from __future__ import annotations

import logging

from poppy_core.bus.dxlbus import DxlBus
from poppy_core.bus.results import SetupResult
from poppy_core.bus.setup import (
    RESET_ALL,
    RESET_KEEP_ID,
    RESET_KEEP_ID_BAUDRATE,
    Progress,
    change_baudrate,
    change_id,
    identify,
    locate,
    new_result,
    say,
    set_angle_limits,
    set_return_delay,
    unlock_eeprom,
    wait_for_answer,
)
from poppy_core.errors import CommunicationError, SetupError
from poppy_core.models import ServoModel, model_by_name

logger = logging.getLogger(__name__)


def _factory_settings(model: ServoModel) -> tuple[int, int]:
    """The model's factory ID and baud rate (from its control table defaults)."""
    id_default = model.register("id").default
    code = model.register("baudrate").default
    if id_default is None or code is None:
        raise SetupError(f"{model.name}: factory ID or baud rate unknown")
    return id_default, model.baudrate_bps(code)


def factory_reset(
    bus: DxlBus,
    motor_id: int,
    keep_id: bool = True,
    keep_baudrate: bool = True,
    *,
    progress: Progress | None = None,
) -> SetupResult:
    """Reset the motor to factory settings without losing it.

    Protocol 2 uses the reset options (all but ID and baud rate, all but ID, all). Protocol 1
    resets everything: the motor is then found at its factory ID and baud rate and, as asked,
    given back its ID and baud rate. The bus ends at the rate the motor answers at.

    Args:
        bus: the bus.
        motor_id: the motor.
        keep_id: keep (or restore) its ID.
        keep_baudrate: keep (or restore) its baud rate.
        progress: called with a line per step.

    Returns:
        Where the motor is afterwards (``motor_id``, ``baudrate``) and what was restored.

    Raises:
        SetupError: the motor does not answer, its factory ID is taken, or it cannot be found
            after the reset.
    """
    _, model = identify(bus, motor_id)
    factory_id, factory_bps = _factory_settings(model)
    old_bps = bus.baudrate
    if bus.proto.has_factory_reset_options:
        option = (
            RESET_KEEP_ID_BAUDRATE
            if keep_id and keep_baudrate
            else RESET_KEEP_ID
            if keep_id
            else RESET_ALL
        )
    else:
        option = RESET_ALL
    id_after = motor_id if option in (RESET_KEEP_ID, RESET_KEEP_ID_BAUDRATE) else factory_id
    bps_after = old_bps if option == RESET_KEEP_ID_BAUDRATE else factory_bps
    if id_after != motor_id:
        bus.baudrate = bps_after
        taken = bus.ping(id_after) is not None
        bus.baudrate = old_bps
        if taken:
            raise SetupError(
                f"factory ID {id_after} is already taken on {bus.port} at {bps_after} bps: "
                f"resetting motor {motor_id} would make two motors share it; unplug the others"
            )
    say(progress, f"motor {motor_id}: factory reset")
    unlock_eeprom(bus, motor_id, model)
    try:
        bus.factory_reset(motor_id, None if option == RESET_ALL else option)
    except CommunicationError as exc:
        logger.debug("factory reset not acknowledged: %s", exc)
    bus.baudrate = bps_after
    if not wait_for_answer(bus, id_after):
        found = locate(bus, id_after)
        raise SetupError(
            f"after its factory reset, motor {motor_id} does not answer as {id_after} at "
            f"{bps_after} bps on {bus.port}"
            + (f"; ID {id_after} answers at {found} bps" if found else "; run `poppy scan`")
        )
    result = new_result(bus, "factory_reset", id_after)
    result.notes.append(f"reset with option {option:#04x}")
    if keep_id and id_after != motor_id:
        say(progress, f"restoring ID {motor_id}")
        change_id(bus, id_after, motor_id, progress=progress)
        result.notes.append(f"ID {motor_id} restored")
    if keep_baudrate and bus.baudrate != old_bps:
        say(progress, f"restoring {old_bps} bps")
        change_baudrate(bus, motor_id, old_bps, progress=progress)
        result.notes.append(f"{old_bps} bps restored")
    result.motor_id = motor_id if keep_id else id_after
    result.baudrate = bus.baudrate
    result.verified = True
    return result


def reset_motor(
    bus: DxlBus,
    motor_id: int,
    model: ServoModel | str | None = None,
    *,
    target_id: int,
    baudrate: int = 1_000_000,
    angle_limits: tuple[float, float] | None = None,
    go_to_zero: bool = False,
    return_delay_us: float = 0.0,
    progress: Progress | None = None,
) -> SetupResult:
    """Prepare a motor for a poppy robot (the old ``poppy-reset-motor``).

    Steps, each verified: check the model, set ID ``target_id``, the return delay, the angle
    limits (if given), the baud rate (last: the bus follows it), then optionally torque on and
    move to 0°.

    Args:
        bus: the bus the motor is on now.
        motor_id: its current ID.
        model: the model it must be (a ``ServoModel`` or a name such as ``"MX-28"``); None
            accepts whatever model answers.
        target_id: the ID it must get.
        baudrate: the rate it must use.
        angle_limits: ``(min_deg, max_deg)`` or None to leave them.
        go_to_zero: enable torque and send it to 0°.
        return_delay_us: the return delay it must have (poppy: 0 µs).
        progress: called with a line per step.

    Raises:
        SetupError: wrong model, ID taken, a step that did not hold.
    """
    wanted = model_by_name(model) if isinstance(model, str) else model
    _, actual = identify(bus, motor_id)
    if wanted is not None and actual.name != wanted.name:
        raise SetupError(f"motor {motor_id} on {bus.port} is a {actual.name}, not a {wanted.name}")
    result = new_result(bus, "reset_motor", motor_id)
    steps = [change_id(bus, motor_id, target_id, progress=progress)]
    steps.append(set_return_delay(bus, target_id, return_delay_us, progress=progress))
    if angle_limits is not None:
        steps.append(set_angle_limits(bus, target_id, *angle_limits, progress=progress))
    steps.append(change_baudrate(bus, target_id, baudrate, progress=progress))
    for step in steps:
        result.changes.update(step.changes)
    if go_to_zero:
        say(progress, f"motor {target_id}: torque on, going to 0°")
        bus.write_register(target_id, actual, "torque_enable", True)
        bus.write_register(target_id, actual, "goal_position", 0.0)
        result.notes.append("sent to 0°")
    result.motor_id = target_id
    result.baudrate = bus.baudrate
    result.verified = True
    say(progress, f"motor {target_id} ({actual.name}) ready at {bus.baudrate} bps")
    return result
