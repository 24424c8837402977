"""ServoModel: one Dynamixel model's control table, aliases, limits and baud-rate codes."""

from __future__ import annotations

import difflib
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from types import MappingProxyType

from poppy_core.errors import RegisterError
from poppy_core.models.converters import Baudrate, SIValue
from poppy_core.models.register import Register

# The names every model resolves, directly or through an alias (docs/internals.md).
COMMON_NAMES: tuple[str, ...] = (
    "model_number",
    "firmware",
    "id",
    "baudrate",
    "return_delay_time",
    "min_position_limit",
    "max_position_limit",
    "temperature_limit",
    "torque_enable",
    "led",
    "goal_position",
    "moving_speed",
    "present_position",
    "present_speed",
    "present_load",
    "present_voltage",
    "present_temperature",
    "moving",
    "status_return_level",
)

# Aliases shared by every model (targets missing from a table are dropped by ``aliases_for``).
_SHARED_ALIASES: dict[str, str] = {
    "firmware_version": "firmware",
    "baud_rate": "baudrate",
    "max_temperature": "temperature_limit",
    "highest_limit_temperature": "temperature_limit",
    "registered_instruction": "registered",
}

# Protocol-1 style tables (AX, MX, XL-320): limits are called CW/CCW angle limits.
_PROTOCOL1_ALIASES: dict[str, str] = {
    "min_position_limit": "cw_angle_limit",
    "max_position_limit": "ccw_angle_limit",
    "goal_speed": "moving_speed",
    "present_velocity": "present_speed",
    "present_input_voltage": "present_voltage",
    "low_voltage_limit": "min_voltage_limit",
    "high_voltage_limit": "max_voltage_limit",
}

# X-series: the closest e-manual register for each protocol-1 name.
_XSERIES_ALIASES: dict[str, str] = {
    "present_speed": "present_velocity",
    # Profile Velocity is the speed the position controller moves at, like protocol-1 Moving Speed
    # (0 = no limit in both).
    "moving_speed": "profile_velocity",
    "goal_speed": "profile_velocity",
    "present_voltage": "present_input_voltage",
    "cw_angle_limit": "min_position_limit",
    "ccw_angle_limit": "max_position_limit",
    "protocol_version": "protocol_type",
    # XL430 has Present Load (%); XM430 and XL330 only Present Current (mA), the closest in meaning.
    "present_load": "present_current",
}


def aliases_for(registers: Mapping[str, Register], xseries: bool) -> dict[str, str]:
    """Return the standard aliases whose target exists in ``registers`` and whose name does not."""
    wanted = dict(_SHARED_ALIASES)
    wanted.update(_XSERIES_ALIASES if xseries else _PROTOCOL1_ALIASES)
    return {
        alias: target
        for alias, target in wanted.items()
        if target in registers and alias not in registers
    }


@dataclass(frozen=True, eq=False)
class ServoModel:
    """Everything poppy knows about one servo model; instances are shared, immutable singletons.

    ``no_load_speed_dps`` and ``stall_torque_nm`` are the datasheet values at the nominal voltage
    given next to each model's definition.
    """

    name: str
    model_numbers: tuple[int, ...]
    protocol: int
    registers: Mapping[str, Register]
    aliases: Mapping[str, str]
    position_range_deg: float
    resolution: int
    no_load_speed_dps: float
    stall_torque_nm: float
    baudrates: Mapping[int, int]
    has_torque_limit: bool

    def __post_init__(self) -> None:
        object.__setattr__(self, "registers", MappingProxyType(dict(self.registers)))
        object.__setattr__(self, "aliases", MappingProxyType(dict(self.aliases)))
        object.__setattr__(self, "baudrates", MappingProxyType(dict(self.baudrates)))
        for alias, target in self.aliases.items():
            if target not in self.registers:
                raise ValueError(f"{self.name}: alias {alias} -> unknown register {target}")
        if not isinstance(self.registers["baudrate"].conversion, Baudrate):
            raise ValueError(f"{self.name}: the baudrate register needs a Baudrate conversion")

    def __repr__(self) -> str:
        return f"ServoModel({self.name!r}, model_numbers={self.model_numbers})"

    def __str__(self) -> str:
        return self.name  # print(motor.model) shows "XL-320", as pypot's model string

    @property
    def model_number(self) -> int:
        """The main model number (the one written to a factory-fresh control table)."""
        return self.model_numbers[0]

    @property
    def table_size(self) -> int:
        """Bytes from address 0 to the end of the last register poppy describes."""
        return max(reg.address + reg.size for reg in self.registers.values())

    def has_register(self, name: str) -> bool:
        """True when ``name`` is a register or an alias of this model."""
        return name in self.registers or name in self.aliases

    def find_register(self, name: str) -> Register | None:
        """The register called ``name`` (or reached through an alias), None when there is none.

        For hot paths that look up names the model may lack (the emulator's firmware); use
        ``register`` where an unknown name is the caller's mistake.
        """
        return self.registers.get(self.aliases.get(name, name))

    def register(self, name: str) -> Register:
        """Return the register called ``name`` (or reached through an alias).

        Raises:
            RegisterError: unknown name; the message lists the closest names.
        """
        found = self.find_register(name)
        if found is not None:
            return found
        candidates = [*self.registers, *self.aliases]
        close = difflib.get_close_matches(name, candidates, n=4, cutoff=0.5)
        hint = f"; did you mean {', '.join(close)}?" if close else ""
        raise RegisterError(f"{self.name} has no register {name!r}{hint}", register=name)

    def decode_table(
        self, data: bytes, names: Iterable[str] | None = None, *, start: int = 0
    ) -> dict[str, SIValue]:
        """SI values of the registers ``names`` (all, in address order, for None) found whole in
        ``data``, bytes read from address ``start``; names the model lacks are left out.

        Raises:
            RegisterError: a raw value that cannot be read (an unknown code).
        """
        if names is None:
            names = [reg.name for reg in sorted(self.registers.values(), key=_address)]
        out: dict[str, SIValue] = {}
        for name in names:
            register = self.find_register(name)
            if register is None:
                continue
            if register.address >= start and register.address + register.size <= start + len(data):
                out[name] = register.decode_si(data, start)
        return out

    def register_at(self, address: int) -> Register | None:
        """Return the register starting at ``address``, if any."""
        for reg in self.registers.values():
            if reg.address == address:
                return reg
        return None

    def default_table(self) -> bytearray:
        """The factory control table (EEPROM defaults, RAM power-on values), zeros elsewhere.

        Registers whose e-manual default is "-" (firmware version, goal and present values) stay 0;
        the emulator fills them in.
        """
        table = bytearray(self.table_size)
        for reg in self.registers.values():
            if reg.default is not None:
                table[reg.address : reg.address + reg.size] = reg.encode(reg.default)
        return table

    def baudrate_bps(self, code: int) -> int:
        """Return the (nominal) bps of baud-rate ``code``.

        Raises:
            RegisterError: the model has no such code.
        """
        reg = self.registers["baudrate"]
        if not reg.min_raw <= code <= reg.max_raw:
            raise RegisterError(
                f"{self.name}: baud-rate code {code} is outside {reg.min_raw}..{reg.max_raw}",
                register="baudrate",
            )
        value = reg.to_si(code)
        assert isinstance(value, int)
        return value

    def baudrate_code(self, bps: int) -> int:
        """Return the baud-rate code for ``bps`` (nominal or exact rate, or within 3 %).

        Raises:
            RegisterError: no code of this model gives that rate.
        """
        return self.registers["baudrate"].from_si(bps)


def _address(register: Register) -> int:
    return register.address
