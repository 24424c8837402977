"""Control-table registers: where each lives, what it holds, how its raw value converts.

The conversions themselves are ``poppy_core.models.converters``; a model's table is built from
compact rows (``build_table``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from poppy_core.errors import RegisterError
from poppy_core.models.converters import Boolean, Choice, Converter, DirectionBit, SIValue

Access = Literal["R", "RW"]
Memory = Literal["EEPROM", "RAM"]


@dataclass(frozen=True)
class Register:
    """One control-table entry: where it lives, what it holds, how to convert it.

    Raw values are plain Python ints, already sign-decoded for ``signed`` registers (use
    :meth:`decode`/:meth:`encode` for the little-endian bytes on the wire).
    """

    name: str
    address: int
    size: int
    access: Access
    memory: Memory
    unit: str
    default: int | None
    min_raw: int
    max_raw: int
    signed: bool
    conversion: Converter

    @property
    def writable(self) -> bool:
        """True when the e-manual marks the register RW."""
        return self.access == "RW"

    def to_si(self, raw: int) -> SIValue:
        """Convert a raw value (as read from the motor) to its SI value.

        Args:
            raw: the register value; for a signed register an unsigned two's-complement value
                (e.g. 0xFFFF for -1 on 2 bytes) is accepted too.

        Returns:
            The SI value (float, int, bool or str depending on the register).
        """
        if self.signed and raw >= 1 << (8 * self.size - 1) and raw < 1 << (8 * self.size):
            raw -= 1 << (8 * self.size)
        try:
            return self.conversion.to_si(raw)
        except (TypeError, ValueError) as exc:
            raise RegisterError(
                f"{self.name}: raw value {raw} cannot be read ({exc})", register=self.name
            ) from exc

    def from_si(self, value: object) -> int:
        """Convert an SI value to the raw value, checking the register's range.

        Read-only registers convert too (``writable`` says whether a write makes sense).

        Raises:
            RegisterError: the value is of the wrong kind or outside the allowed range.
        """
        allowed = self.conversion.describe(self.min_raw, self.max_raw)
        try:
            raw = self.conversion.from_si(value)
        except (TypeError, ValueError, OverflowError) as exc:
            raise RegisterError(
                f"{self.name}: {value!r} is not allowed ({exc}); allowed: {allowed}",
                register=self.name,
            ) from exc
        if not self.min_raw <= raw <= self.max_raw:
            raise RegisterError(
                f"{self.name}: {value!r} is out of range; allowed: {allowed}", register=self.name
            )
        return raw

    def parse(self, text: str) -> SIValue:
        """Turn typed text (a command line, a form field) into the SI value ``from_si`` takes.

        ``on``/``off`` (or true/false, 1/0, yes/no) for on/off registers, a name or a number for
        choices (XL-320 LED colours; ``on`` is white), a number otherwise. The range is not
        checked here.

        Raises:
            RegisterError: text that is not a value of this kind (the message says what is).
        """
        lowered = text.strip().lower()
        if isinstance(self.conversion, Boolean):
            if lowered in ("on", "true", "1", "yes"):
                return True
            if lowered in ("off", "false", "0", "no"):
                return False
            raise RegisterError(f"{self.name} takes on or off, not {text!r}", register=self.name)
        if isinstance(self.conversion, Choice):
            if lowered == "on" and self.conversion.on is not None:
                return self.conversion.on
            return int(lowered) if lowered.isdigit() else lowered
        try:
            number = float(lowered)
        except ValueError:
            raise RegisterError(
                f"{self.name} takes a number in {self.unit or 'raw units'}, not {text!r}",
                register=self.name,
            ) from None
        return int(number) if number.is_integer() else number

    def switched(self, on: bool) -> SIValue:
        """The value that turns this register on or off: True/False, or for the XL-320 LED
        (colours) ``"white"`` (all three) and ``"off"``.

        Raises:
            RegisterError: a register that does not switch (a number, a choice without "on").
        """
        if isinstance(self.conversion, Boolean):
            return on
        if isinstance(self.conversion, Choice) and self.conversion.on is not None:
            return self.conversion.on if on else self.conversion.to_si(0)
        raise RegisterError(f"{self.name} is not an on/off register", register=self.name)

    def si_range(self) -> tuple[float, float]:
        """(lowest, highest) SI value it holds; a speed's or load's magnitude (bit 10: sign)."""
        if isinstance(self.conversion, DirectionBit):
            return 0.0, float(self.conversion.to_si(min(self.max_raw, 0x3FF)))
        ends = float(self.to_si(self.min_raw)), float(self.to_si(self.max_raw))
        return min(ends), max(ends)

    def decode_si(self, data: bytes, start: int | None = None) -> SIValue:
        """The SI value of this register in ``data``, bytes read from address ``start`` (None:
        ``data`` starts at this register).

        Raises:
            RegisterError: ``data`` does not hold the whole register, or a raw value it cannot
                read.
        """
        offset = 0 if start is None else self.address - start
        if offset < 0:
            raise RegisterError(
                f"{self.name}: data from address {start} does not hold address {self.address}",
                register=self.name,
            )
        return self.to_si(self.decode(data[offset : offset + self.size]))

    def decode(self, data: bytes) -> int:
        """Read this register's raw value from its little-endian bytes."""
        if len(data) != self.size:
            raise RegisterError(
                f"{self.name}: expected {self.size} bytes, got {len(data)}", register=self.name
            )
        return int.from_bytes(data, "little", signed=self.signed)

    def encode(self, raw: int) -> bytes:
        """Write a raw value as this register's little-endian bytes."""
        try:
            return raw.to_bytes(self.size, "little", signed=self.signed)
        except OverflowError as exc:
            raise RegisterError(
                f"{self.name}: raw value {raw} does not fit in {self.size} bytes",
                register=self.name,
            ) from exc


# A table row: (name, address, size, access, default, min_raw, max_raw, conversion).
Row = tuple[str, int, int, Access, int | None, int, int, Converter]


def build_table(rows: list[Row], ram_start: int) -> dict[str, Register]:
    """Build the registers of a control table from compact rows.

    Args:
        rows: one tuple per register, in address order.
        ram_start: first RAM address (24 for protocol-1 tables, 64 for X-series).

    Returns:
        Registers by name; ``signed`` is set when ``min_raw`` is negative.
    """
    table: dict[str, Register] = {}
    for name, address, size, access, default, min_raw, max_raw, conversion in rows:
        if name in table:
            raise ValueError(f"duplicate register {name}")
        table[name] = Register(
            name=name,
            address=address,
            size=size,
            access=access,
            memory="EEPROM" if address < ram_start else "RAM",
            unit=conversion.unit,
            default=default,
            min_raw=min_raw,
            max_raw=max_raw,
            signed=min_raw < 0,
            conversion=conversion,
        )
    return table
