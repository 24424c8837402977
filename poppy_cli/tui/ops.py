"""Blocking motor operations the TUI runs in thread workers: writes, setup, toggles, resets."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

from poppy_cli.tui.busio import BusPool, MotorRef, SIValue
from poppy_core.bus import change_baudrate, change_id, factory_reset, reboot
from poppy_core.errors import PoppyError, SetupError
from poppy_core.models.register import Register


@dataclass
class WriteOutcome:
    """What a write to one or several motors did.

    Attributes:
        register: the register written.
        value: the SI value asked for.
        done: motors written (after the change: a new ID or rate is already applied).
        failed: motor and error message, for each motor that refused.
        renamed: old motor -> the same motor after an ID or baud-rate change.
    """

    register: str
    value: SIValue
    done: list[MotorRef] = field(default_factory=list)
    failed: list[tuple[MotorRef, str]] = field(default_factory=list)
    renamed: dict[MotorRef, MotorRef] = field(default_factory=dict)


def write_value(
    pool: BusPool, motors: Sequence[MotorRef], register: str, value: SIValue
) -> WriteOutcome:
    """Write ``value`` (SI) to ``register`` of every motor; ID and baud rate use the setup path.

    A motor refusing (e.g. an EEPROM write while its torque is on) does not stop the others:
    its error lands in ``failed``.
    """
    outcome = WriteOutcome(register, value)
    if register == "id" and len(motors) > 1:
        for motor in motors:
            outcome.failed.append((motor, "one ID cannot be given to several motors"))
        return outcome
    for motor in motors:
        try:
            model = motor.servo_model()
            name = model.register(register).name
            with pool.bus(motor) as bus:
                if name == "id":
                    change_id(bus, motor.id, int(value))
                    after = motor.moved(id=int(value))
                elif name == "baudrate":
                    result = change_baudrate(bus, motor.id, int(value))
                    after = motor.moved(baudrate=result.baudrate)
                else:
                    bus.write_register(motor.id, model, name, value)
                    after = motor
        except PoppyError as exc:
            outcome.failed.append((motor, str(exc)))
            continue
        outcome.done.append(after)
        if after != motor:
            outcome.renamed[motor] = after
    return outcome


def toggled(current: SIValue | None, register: Register) -> SIValue:
    """The value a toggle key writes: booleans flip, an XL-320 LED colour goes off/white."""
    return register.switched(current is None or current == register.switched(False))


def restart(pool: BusPool, motor: MotorRef, action: str) -> MotorRef:
    """Reboot (``"reboot"``) or factory-reset (``"reset"``, keeping ID and rate) a motor.

    Returns:
        Where the motor answers afterwards.

    Raises:
        SetupError: unknown action, or the setup operation failed.
    """
    with pool.bus(motor, timeout_s=5.0) as bus:
        if action == "reboot":
            reboot(bus, motor.id)
            return motor
        if action == "reset":
            result = factory_reset(bus, motor.id, keep_id=True, keep_baudrate=True)
            return motor.moved(id=result.motor_id, baudrate=result.baudrate)
    raise SetupError(f"unknown action {action!r}")
