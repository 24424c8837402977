"""pypot's ``DxlIO`` calls spanning several registers or naming them its own way (modes, gains).

pypot grouped registers a servo keeps side by side (``pid_gain``, ``voltage_limit``,
``goal_position_speed_load``...) and named others its own way (``alarm_shutdown``,
``highest_temperature_limit``). These calls answer as pypot 5.0.2's did on the same bus (the
expected values of ``tests/bus/test_dxlio.py`` were recorded from pypot's ``DxlIO``), in poppy's
units: the register facts come from the Robotis e-manuals, the names from pypot's documentation.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Mapping, Sequence
from typing import Any, Protocol

from poppy_core.bus.dxlbus import DxlBus
from poppy_core.errors import ArgumentError
from poppy_core.models import ServoModel
from poppy_core.protocol.v1 import V1_ERROR_BITS

# Status return levels by code (e-manual: 0 ping only, 1 reads, 2 every instruction).
STATUS_LEVELS = ("never", "read", "always")
# The registers pypot's pairs and triples stand for, in pypot's order.
GROUPS: dict[str, tuple[str, ...]] = {
    "pid_gain": ("p_gain", "i_gain", "d_gain"),
    "compliance_margin": ("cw_compliance_margin", "ccw_compliance_margin"),
    "compliance_slope": ("cw_compliance_slope", "ccw_compliance_slope"),
    "voltage_limit": ("min_voltage_limit", "max_voltage_limit"),
    "goal_position_speed_load": ("goal_position", "moving_speed", "torque_limit"),
    "present_position_speed_load": ("present_position", "present_speed", "present_load"),
}
# Registers pypot's DxlIO capped to their range when written (its speed, position and gain
# conversions): poppy's DxlIO caps them too; a value beyond any other register is refused.
CAPPED = frozenset({"goal_position", "moving_speed", "p_gain", "i_gain", "d_gain"})
# pypot's names of single registers.
RENAMED = {
    "highest_temperature_limit": "temperature_limit",
    "alarm_LED": "alarm_led",
    "LED": "led",
}
# pypot's control table, in its order and with its keys: (key, the call answering it).
CONTROL_TABLE = (
    ("model", "model"),
    ("firmware", "firmware"),
    ("id", "id"),
    ("baudrate", "baudrate"),
    ("return delay time", "return_delay_time"),
    ("angle limit", "angle_limit"),
    ("highest temperature limit", "highest_temperature_limit"),
    ("voltage limit", "voltage_limit"),
    ("max torque", "max_torque"),
    ("status return level", "status_return_level"),
    ("alarm LED", "alarm_LED"),
    ("alarm shutdown", "alarm_shutdown"),
    ("torque_enable", "torque_enable"),
    ("LED", "LED"),
    ("pid gain", "pid_gain"),
    ("compliance margin", "compliance_margin"),
    ("compliance slope", "compliance_slope"),
    ("goal position", "goal_position"),
    ("moving speed", "moving_speed"),
    ("torque limit", "torque_limit"),
    ("present position", "present_position"),
    ("present speed", "present_speed"),
    ("present load", "present_load"),
    ("present voltage", "present_voltage"),
    ("present temperature", "present_temperature"),
    ("moving", "moving"),
)


def alarm_names(raw: int) -> tuple[str, ...]:
    """The alarms set in a protocol 1 alarm byte, highest bit first, as pypot named them."""
    return tuple(
        f"{name.title()} Error"
        for bit, name in reversed(list(enumerate(V1_ERROR_BITS)))
        if raw & (1 << bit)
    )


def alarm_byte(names: Iterable[str]) -> int:
    """The alarm byte for alarm names (``'Overload Error'`` or ``'overload'``)."""
    if isinstance(names, str):
        names = [names]
    known = {name: bit for bit, name in enumerate(V1_ERROR_BITS)}
    raw = 0
    for name in names:
        key = str(name).lower().removesuffix(" error").strip()
        if key not in known:
            choices = ", ".join(f"{n.title()} Error" for n in V1_ERROR_BITS)
            raise ArgumentError(f"unknown alarm {name!r}; choose among {choices}", field="alarm")
        raw |= 1 << known[key]
    return raw


class RegisterIO(Protocol):
    """What pypot's calls need of an IO: its bus, registers by name and each motor's model."""

    @property
    def bus(self) -> DxlBus:
        """The bus the IO speaks on."""
        ...

    def get(self, register: str, ids: Iterable[int]) -> tuple[Any, ...]:
        """Register ``register`` of each motor, in SI units."""
        ...

    def set(self, register: str, value_for_id: Mapping[int, Any]) -> None:
        """Write ``register`` of each motor (``{id: value}``, SI units)."""
        ...

    def model_of(self, id: int) -> ServoModel:
        """The model of motor ``id``."""
        ...

    def get_angle_limit(self, ids: Iterable[int]) -> tuple[tuple[float, float], ...]:
        """(min, max) position limits in degrees."""
        ...


class PypotCalls:
    """pypot's grouped and renamed calls over a ``RegisterIO`` (``DxlIO`` gives itself).

    Args:
        io: reads and writes registers by name.
    """

    def __init__(self, io: RegisterIO) -> None:
        self._io = io

    # -- joint and wheel modes --------------------------------------------------------------------

    def get_control_mode(self, ids: Iterable[int]) -> tuple[str, ...]:
        """``'joint'`` or ``'wheel'`` (protocol 1: wheel when both angle limits are 0)."""
        return tuple(self._mode(motor_id) for motor_id in _ids(ids))

    def set_wheel_mode(self, ids: Iterable[int]) -> None:
        """Turn the motors endlessly (speed control): both angle limits 0 on protocol 1."""
        self.set_control_mode(dict.fromkeys(_ids(ids), "wheel"))

    def set_joint_mode(self, ids: Iterable[int]) -> None:
        """Back to position control over the motor's whole range."""
        self.set_control_mode(dict.fromkeys(_ids(ids), "joint"))

    def set_control_mode(self, mode_for_id: Mapping[int, str]) -> None:
        """``{id: 'joint' | 'wheel'}``."""
        for motor_id, mode in _mapping(mode_for_id).items():
            if mode not in ("joint", "wheel"):
                raise ArgumentError(
                    f"control mode must be 'joint' or 'wheel', got {mode!r}", field="mode"
                )
            model = self._io.model_of(motor_id)
            if model.has_register("control_mode"):
                self._io.bus.write(
                    motor_id,
                    model.register("control_mode").address,
                    bytes([1 if mode == "wheel" else 2]),
                )
                continue
            cw, ccw = model.register("cw_angle_limit"), model.register("ccw_angle_limit")
            top = 0 if mode == "wheel" else ccw.max_raw
            self._io.bus.write(motor_id, cw.address, cw.encode(0) + ccw.encode(top))

    def _mode(self, motor_id: int) -> str:
        model = self._io.model_of(motor_id)
        if model.has_register("control_mode"):
            raw = self._io.bus.read(motor_id, model.register("control_mode").address, 1)[0]
            return "wheel" if raw == 1 else "joint"
        cw = model.register("cw_angle_limit")
        data = self._io.bus.read(motor_id, cw.address, 2 * cw.size)
        return "wheel" if not any(data) else "joint"

    # -- registers pypot grouped or named its own way ---------------------------------------------

    def get_alarm_shutdown(self, ids: Iterable[int]) -> tuple[tuple[str, ...], ...]:
        """The alarms that turn the torque off, by name (``('Overload Error', ...)``)."""
        return tuple(alarm_names(int(raw)) for raw in self._io.get("shutdown", ids))

    def set_alarm_shutdown(self, value_for_id: Mapping[int, Iterable[str]]) -> None:
        """``{id: ('Overload Error', ...)}``."""
        self._io.set("shutdown", {i: alarm_byte(v) for i, v in _mapping(value_for_id).items()})

    def get_alarm_LED(self, ids: Iterable[int]) -> tuple[tuple[str, ...], ...]:
        """The alarms that blink the LED, by name."""
        return tuple(alarm_names(int(raw)) for raw in self._io.get("alarm_led", ids))

    def set_alarm_LED(self, value_for_id: Mapping[int, Iterable[str]]) -> None:
        """``{id: ('Overheating Error', ...)}``."""
        self._io.set("alarm_led", {i: alarm_byte(v) for i, v in _mapping(value_for_id).items()})

    def get_status_return_level(self, ids: Iterable[int]) -> tuple[str, ...]:
        """``'never'``, ``'read'`` or ``'always'``."""
        return tuple(STATUS_LEVELS[int(raw)] for raw in self._io.get("status_return_level", ids))

    def set_status_return_level(self, value_for_id: Mapping[int, str | int]) -> None:
        """``{id: 'always'}`` (or the code 0-2)."""
        codes = {}
        for motor_id, level in _mapping(value_for_id).items():
            if level not in STATUS_LEVELS and level not in range(3):
                raise ArgumentError(
                    f"status return level must be one of {STATUS_LEVELS}, got {level!r}",
                    field="status_return_level",
                )
            codes[motor_id] = STATUS_LEVELS.index(level) if isinstance(level, str) else level
        self._io.set("status_return_level", codes)

    def get_drive_mode(self, ids: Iterable[int]) -> tuple[tuple[str, str], ...]:
        """(``'normal'``/``'reverse'``, ``'master'``/``'slave'``); a motor without dual-joint
        drive (MX-28, AX...) is always normal and master."""
        modes = []
        for motor_id in _ids(ids):
            model = self._io.model_of(motor_id)
            raw = (
                int(self._io.get("drive_mode", [motor_id])[0])
                if model.has_register("drive_mode")
                else 0
            )
            modes.append(("reverse" if raw & 1 else "normal", "slave" if raw & 2 else "master"))
        return tuple(modes)

    def get_control_table(self, ids: Iterable[int]) -> tuple[dict[str, Any], ...]:
        """Every register pypot listed that the motor has, keyed by pypot's names."""
        tables = []
        for motor_id in _ids(ids):
            model = self._io.model_of(motor_id)
            table: dict[str, Any] = {}
            for key, call in CONTROL_TABLE:
                reader = self._reader(model, call)
                if reader is not None:
                    table[key] = reader([motor_id])[0]
            tables.append(table)
        return tuple(tables)

    def _reader(self, model: ServoModel, call: str) -> Callable[[list[int]], Sequence[Any]] | None:
        if call == "model":
            return lambda ids: [model.name]
        if call == "angle_limit":
            return self._io.get_angle_limit
        registers = GROUPS.get(call, (RENAMED.get(call, call),))
        if call == "alarm_LED" or call in ("alarm_shutdown", "status_return_level"):
            return getattr(self, f"get_{call}")  # type: ignore[no-any-return]
        if all(model.has_register(name) for name in registers):
            return lambda ids: self.get_grouped(call, ids)
        return None

    def get_grouped(self, name: str, ids: Iterable[int]) -> tuple[Any, ...]:
        """pypot's register ``name`` (a group, a renamed or a plain one) for each motor."""
        registers = GROUPS.get(name)
        chosen = _ids(ids)
        if registers is None:
            return self._io.get(RENAMED.get(name, name), chosen)
        columns = [self._io.get(register, chosen) for register in registers]
        return tuple(zip(*columns, strict=True))

    def set_grouped(self, name: str, value_for_id: Mapping[int, Any]) -> None:
        """Write pypot's register ``name``: a group takes a tuple per motor."""
        registers = GROUPS.get(name)
        values = _mapping(value_for_id)
        if registers is None:
            self._io.set(RENAMED.get(name, name), values)
            return
        for motor_id, value in values.items():
            if (
                isinstance(value, str)
                or not isinstance(value, Sequence)
                or len(value) != len(registers)
            ):
                listed = ", ".join(registers)
                raise ArgumentError(
                    f"{name} takes {len(registers)} values per motor ({listed}), got {value!r}",
                    field=name,
                )
            for register, part in zip(registers, value, strict=True):
                self._io.set(register, {motor_id: part})


def _ids(ids: Iterable[int]) -> list[int]:
    if isinstance(ids, int | Mapping):
        raise ArgumentError(f"give a list of IDs, not {ids!r} (e.g. [{ids}])", field="ids")
    return [int(i) for i in ids]


def _mapping(values: Mapping[int, Any]) -> dict[int, Any]:
    if not isinstance(values, Mapping):
        raise ArgumentError(f"give {{id: value}}, not {values!r} (e.g. {{4: 0}})", field="values")
    return {int(k): v for k, v in values.items()}


def capped(model: ServoModel, register: str, value: Any) -> Any:
    """``value`` clamped to the register's range when pypot capped that register (a finite
    number only: anything else goes on to the register's own check, which refuses it)."""
    if register not in CAPPED or not model.has_register(register):
        return value
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        return value
    low, high = model.register(register).si_range()
    if register == "moving_speed":  # signed in wheel mode: the magnitude is capped
        return math.copysign(min(abs(value), high), value)
    return min(max(float(value), low), high)
