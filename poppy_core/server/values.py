"""Motor registers over the network: JSON-ready reads and validated writes.

A write is checked in full (type, finiteness, the model's register range) before the motor is
touched, so a bad value is refused with an ``ApiError("invalid")`` and never reaches the bus.
The rules are the library's (``poppy_core.checks``, ``trajectory.control_name``); a goal outside
the angle limits is clamped to them, as ``Motor.goal_position`` does (docs/rest.md, "Arguments
and errors").
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from poppy_core import checks
from poppy_core.errors import ArgumentError, PoppyError, RegisterError
from poppy_core.models import ServoModel
from poppy_core.robot import Motor
from poppy_core.robot import registers as regs
from poppy_core.server.errors import ApiError
from poppy_core.trajectory import CONTROLS, clamp_goal, control_name

REGISTER_TIP = "the registers of a motor are listed by /motors/<motor_name>/registers/list.json"

STATE_REGISTERS = (
    "present_position",
    "present_speed",
    "present_load",
    "present_temperature",
    "led",
)
"""What the WebSocket stream sends for every motor (pypot's ws server fields)."""


PLAIN: frozenset[type] = frozenset({int, str, bool, type(None)})
"""Types whose values are JSON as they are (floats are not: NaN and infinities are not JSON)."""


def jsonable(value: Any) -> Any:
    """``value`` as plain JSON data (tuples as lists, models by name, NaN/inf as None)."""
    kind = type(value)  # the exact JSON types first, without isinstance (/robot.json's rebuild)
    if kind is float:
        return value if value - value == 0.0 else None  # finite (inf - inf and nan are nan)
    if kind is bool or kind is str or kind is int or value is None:
        return value
    if kind is list or kind is tuple:
        return [v if type(v) in PLAIN else jsonable(v) for v in value]
    if kind is dict:
        return {str(k): v if type(v) in PLAIN else jsonable(v) for k, v in value.items()}
    if isinstance(value, bool | str | int):
        return value
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, ServoModel):
        return value.name
    if isinstance(value, np.generic):
        return jsonable(value.item())
    if isinstance(value, np.ndarray):
        return [jsonable(v) for v in value.tolist()]
    if isinstance(value, Mapping):
        return {str(k): jsonable(v) for k, v in value.items()}
    if isinstance(value, list | tuple | set | frozenset):
        return [jsonable(v) for v in value]
    return str(value)


def read_register(motor: Motor, name: str) -> Any:
    """The JSON value of register ``name`` of ``motor``.

    Raises:
        ApiError: the motor has no such register.
    """
    if name not in motor.registers:
        raise ApiError(
            "not_found",
            f"motor {motor.name!r} has no register {name!r} (registers: "
            f"{', '.join(motor.registers)})",
            tip=REGISTER_TIP,
        )
    try:
        return jsonable(getattr(motor, name))
    except RegisterError as exc:
        raise ApiError("not_found", str(exc), tip=REGISTER_TIP) from None


def motor_registers(motor: Motor) -> dict[str, Any]:
    """Every register of ``motor`` and its JSON value."""
    out: dict[str, Any] = {}
    for name in motor.registers:
        try:
            value = getattr(motor, name)
        except RegisterError:
            continue
        out[name] = value if type(value) in PLAIN else jsonable(value)
    return out


def motor_state(motor: Motor) -> dict[str, Any]:
    """The streamed state of one motor (present position, speed, load, temperature, LED)."""
    return {name: jsonable(getattr(motor, name)) for name in STATE_REGISTERS}


# -- validation ------------------------------------------------------------------------------


def _bad(motor: Motor, name: str, reason: str) -> ApiError:
    return ApiError("invalid", f"{motor.name}.{name}: {reason}", tip=REGISTER_TIP)


def number(motor: Motor, name: str, value: Any) -> float:
    """``value`` as a finite float (JSON numbers only; the rule is ``checks.number``)."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise _bad(motor, name, f"expected a number, got {json_type(value)}")
    try:
        return checks.number(value, f"{motor.name}.{name}")
    except ArgumentError as exc:
        raise ApiError("invalid", str(exc), tip=REGISTER_TIP) from None


def json_type(value: Any) -> str:
    """The JSON name of ``value``'s type (for messages)."""
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "a boolean"
    if isinstance(value, int | float):
        return "a number"
    if isinstance(value, str):
        return "a string"
    if isinstance(value, list | tuple):
        return "an array"
    if isinstance(value, Mapping):
        return "an object"
    return type(value).__name__


def _fits(motor: Motor, register: str, value: object, name: str) -> None:
    try:
        motor.model.register(register).from_si(value)
    except RegisterError as exc:
        raise _bad(motor, name, str(exc)) from None


def check_position(motor: Motor, name: str, value: Any) -> float:
    """A goal position: a finite number, clamped to the motor's angle limits (user frame).

    The library's rule (``Motor.goal_position`` clamps, as pypot did): the answer says the
    clamped value. A wheel has no limits.
    """
    position = number(motor, name, value)
    return clamp_goal(position, None if motor.wheel_mode else motor.angle_limit)


def _goal_speed(motor: Motor, name: str, value: Any) -> float:
    speed = number(motor, name, value)
    top = motor.model.no_load_speed_dps
    if abs(speed) > top:
        raise _bad(motor, name, f"|{speed:g}| deg/s is above the servo's {top:g} deg/s")
    return speed


def _moving_speed(motor: Motor, name: str, value: Any) -> float:
    speed = number(motor, name, value)
    if speed < 0:
        raise _bad(motor, name, "a speed limit is a magnitude (>= 0)")
    # Beyond the register's top: capped to it, as pypot's REST and the Motor do.
    return min(speed, regs.si_range(motor.model.register("moving_speed"))[1])


def _torque(motor: Motor, name: str, value: Any) -> float:
    if not motor.model.has_torque_limit:
        raise _bad(motor, name, f"{motor.model.name} has no torque limit")
    torque = number(motor, name, value)
    _fits(motor, "torque_limit", torque, name)
    return torque


def _boolean(motor: Motor, name: str, value: Any) -> bool:
    if not isinstance(value, bool):
        raise _bad(motor, name, f"expected true or false, got {json_type(value)}")
    return value


def _behavior(motor: Motor, name: str, value: Any) -> str:
    if value not in ("dummy", "safe"):
        raise _bad(motor, name, "expected 'dummy' or 'safe'")
    return str(value)


def _goto_behavior(motor: Motor, name: str, value: Any) -> str:
    if not isinstance(value, str):
        raise _bad(motor, name, f"expected {' or '.join(map(repr, CONTROLS))}")
    try:
        control_name(value)
    except ArgumentError as exc:
        raise _bad(motor, name, str(exc)) from None
    return value


def _led(motor: Motor, name: str, value: Any) -> Any:
    if not isinstance(value, bool | str | int):
        raise _bad(motor, name, f"expected a boolean or a colour name, got {json_type(value)}")
    _fits(motor, "led", value, name)
    return value


def _triple(motor: Motor, name: str, value: Any) -> tuple[float, float, float]:
    names = regs.pid_names(motor.model)
    if names is None:
        raise _bad(motor, name, f"{motor.model.name} has no PID gains")
    if not isinstance(value, list | tuple) or len(value) != 3:
        raise _bad(motor, name, "expected [P, I, D]")
    gains = tuple(
        regs.capped(motor.model.register(register), number(motor, name, v), name)
        for register, v in zip(names, value, strict=True)
    )  # beyond a gain register's range: capped, as pypot's REST and the Motor do
    return gains[0], gains[1], gains[2]


def _pair_of(registers: tuple[str, str]) -> Callable[[Motor, str, Any], tuple[int, int]]:
    def check(motor: Motor, name: str, value: Any) -> tuple[int, int]:
        if not regs.has_compliance_slopes(motor.model):
            raise _bad(motor, name, f"{motor.model.name} has no compliance margin/slope")
        items = [value, value] if not isinstance(value, list | tuple) else list(value)
        if len(items) != 2 or any(isinstance(v, bool) or not isinstance(v, int) for v in items):
            raise _bad(motor, name, "expected an integer or [cw, ccw] integers")
        for register, item in zip(registers, items, strict=True):
            _fits(motor, register, item, name)
        return items[0], items[1]

    return check


def _angle_limit(motor: Motor, name: str, value: Any) -> tuple[float, float]:
    if not isinstance(value, list | tuple) or len(value) != 2:
        raise _bad(motor, name, "expected [min, max] in degrees")
    low, high = (number(motor, name, v) for v in value)
    if not low < high:
        raise _bad(motor, name, "expected min < max")
    register = motor.model.register("min_position_limit")
    ends = sorted(
        motor.to_user(float(register.to_si(r))) for r in (register.min_raw, register.max_raw)
    )
    if low < ends[0] - 1e-6 or high > ends[1] + 1e-6:
        raise _bad(motor, name, f"limits must lie within [{ends[0]:g}, {ends[1]:g}]")
    return low, high


Checker = Callable[[Motor, str, Any], Any]

WRITABLE: dict[str, Checker] = {
    "goal_position": check_position,
    "goal_speed": _goal_speed,
    "moving_speed": _moving_speed,
    "torque_limit": _torque,
    "max_torque": _torque,
    "compliant": _boolean,
    "compliant_behavior": _behavior,
    "safe_compliant": _boolean,
    "goto_behavior": _goto_behavior,
    "led": _led,
    "pid": _triple,
    "compliance_margin": _pair_of(regs.AX_MARGINS),
    "compliance_slope": _pair_of(regs.AX_SLOPES),
    "angle_limit": _angle_limit,
}
"""Registers a client may write, each with the check its value must pass."""


def check_write(motor: Motor, name: str, value: Any) -> Any:
    """The checked value to set, or an ``ApiError`` (unknown or read-only register, bad value)."""
    if name not in motor.registers:
        raise ApiError(
            "not_found", f"motor {motor.name!r} has no register {name!r}", tip=REGISTER_TIP
        )
    checker = WRITABLE.get(name)
    if checker is None:
        writable = ", ".join(n for n in WRITABLE if n in motor.registers)
        raise ApiError(
            "invalid", f"{motor.name}.{name} is read-only (writable: {writable})", tip=REGISTER_TIP
        )
    return checker(motor, name, value)


def write_register(motor: Motor, name: str, value: Any) -> Any:
    """Check ``value`` then set it; returns the value set.

    Raises:
        ApiError: unknown or read-only register, or a value the check refuses.
    """
    checked = check_write(motor, name, value)
    apply_checked(motor, name, checked)
    return checked


def apply_checked(motor: Motor, name: str, checked: Any) -> None:
    """Set a value ``check_write`` accepted."""
    try:
        setattr(motor, name, checked)
    except PoppyError as exc:
        raise _bad(motor, name, str(exc)) from None
