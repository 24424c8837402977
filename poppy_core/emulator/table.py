"""A virtual motor's control table: raw bytes plus the firmware's write checks (access, range)."""

from __future__ import annotations

import logging

from poppy_core.errors import RegisterError
from poppy_core.models import Register, ServoModel
from poppy_core.protocol import ErrorCodes, protocol_for

logger = logging.getLogger(__name__)

# The status error byte of each kind of refusal is the protocol's (``DxlProtocol.error_codes``).


class ControlTable:
    """Raw control table of one motor, with the checks its firmware makes on writes.

    Args:
        model: the servo model (gives the registers and the factory values).
    """

    def __init__(self, model: ServoModel) -> None:
        self.model = model
        self.proto = protocol_for(model.protocol)
        self.codes: ErrorCodes = self.proto.error_codes
        self.data = model.default_table()
        self._by_address: dict[int, Register] = {}
        for register in model.registers.values():
            self._by_address.setdefault(register.address, register)
        # Each byte of the table -> the register covering it (None for reserved bytes).
        self._owner: list[Register | None] = [None] * len(self.data)
        for register in self._by_address.values():
            for offset in range(register.size):
                if register.address + offset < len(self._owner):
                    self._owner[register.address + offset] = register

    # ------------------------------------------------------------------ registers

    def find(self, name: str) -> Register | None:
        """Return the register called ``name`` (or an alias of it), None when the model lacks it."""
        return self.model.find_register(name)

    def get(self, name: str, default: int = 0) -> int:
        """Raw value of register ``name`` (``default`` when the model does not have it)."""
        register = self.find(name)
        if register is None:
            return default
        return self.raw(register)

    def raw(self, register: Register) -> int:
        """Raw (sign-decoded) value of ``register``."""
        chunk = bytes(self.data[register.address : register.address + register.size])
        return register.decode(chunk)

    def set(self, name: str, raw: int) -> None:
        """Store a raw value in register ``name`` without checks (the firmware's own writes)."""
        register = self.find(name)
        if register is not None:
            self.store(register, raw)

    def store(self, register: Register, raw: int) -> None:
        """Store a raw value in ``register`` without checks, clamped to what its bytes hold."""
        bits = 8 * register.size
        low, high = (
            (-(1 << (bits - 1)), (1 << (bits - 1)) - 1)
            if register.signed
            else (
                0,
                (1 << bits) - 1,
            )
        )
        raw = min(max(raw, low), high)
        self.data[register.address : register.address + register.size] = register.encode(raw)

    def set_si(self, name: str, value: float) -> None:
        """Store an SI value in register ``name``, clamped to the register's range."""
        register = self.find(name)
        if register is None:
            return
        try:
            raw = register.from_si(value)
        except RegisterError:
            ends = (register.to_si(register.min_raw), register.to_si(register.max_raw))
            if not all(isinstance(end, int | float) for end in ends):
                return
            low, high = sorted(float(end) for end in ends)
            try:
                raw = register.from_si(min(max(value, low), high))
            except RegisterError:
                logger.debug("cannot store %r in %s", value, register.name)
                return
        self.store(register, raw)

    def get_si(self, name: str) -> float | None:
        """SI value of register ``name`` as a float (None when the model lacks it)."""
        register = self.find(name)
        if register is None:
            return None
        value = register.to_si(self.raw(register))
        return float(value) if isinstance(value, int | float) else None

    # ------------------------------------------------------------------ access checks

    def check_read(self, address: int, length: int) -> int:
        """Error byte for reading ``length`` bytes at ``address`` (0 when allowed)."""
        if length < 0 or address + length > len(self.data):
            return self.codes.access
        return 0

    def touched(self, address: int, length: int) -> list[Register]:
        """Registers that a write of ``length`` bytes at ``address`` touches (in address order)."""
        seen: list[Register] = []
        for index in range(address, min(address + length, len(self.data))):
            register = self._owner[index]
            if register is not None and (not seen or seen[-1] is not register):
                seen.append(register)
        return seen

    def check_write(self, address: int, data: bytes, *, torque_on: bool) -> int:
        """Error byte for writing ``data`` at ``address`` (0 when the firmware accepts it).

        Checks, in order: inside the table, no read-only register, EEPROM lock (protocol 2
        firmware only: XL-320 and X-series refuse EEPROM writes while torque is on; protocol 1
        AX/MX firmware accepts them), whole registers only (protocol 2), values in range.
        """
        codes = self.codes
        if not data or address + len(data) > len(self.data):
            return codes.access
        touched = self.touched(address, len(data))
        if any(not register.writable for register in touched):
            return codes.access
        if (
            self.proto.torque_locks_eeprom
            and torque_on
            and any(register.memory == "EEPROM" for register in touched)
        ):
            return codes.eeprom_locked
        end = address + len(data)
        for register in touched:
            start, stop = register.address, register.address + register.size
            if start < address or stop > end:
                if self.proto.whole_registers_only:
                    return codes.length
                continue
            raw = register.decode(bytes(data[start - address : stop - address]))
            if not register.min_raw <= raw <= register.max_raw:
                return codes.range
        return 0

    def write(self, address: int, data: bytes) -> None:
        """Store ``data`` at ``address`` (after :meth:`check_write` accepted it)."""
        self.data[address : address + len(data)] = data

    def read(self, address: int, length: int) -> bytes:
        """Bytes ``address .. address + length`` of the table."""
        return bytes(self.data[address : address + length])

    def pending_value(self, name: str, address: int, data: bytes) -> int | None:
        """Raw value register ``name`` would take if ``data`` were written at ``address``."""
        register = self.find(name)
        if register is None:
            return None
        start, stop = register.address, register.address + register.size
        if start < address or stop > address + len(data):
            return None
        return register.decode(bytes(data[start - address : stop - address]))
