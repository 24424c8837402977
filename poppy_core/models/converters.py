"""The small converters turning a register's raw value into its SI value and back.

Sign conventions (e-manual): counter-clockwise (CCW) is positive. Registers that carry a
direction in bit 10 (protocol-1 speeds and loads, XL-320 too) report CCW for ``0..1023`` and CW
for ``1024..2047``; they convert to a *negative* SI value when the CW bit is set. ``0`` and
``1024`` both mean "zero"; ``to_si(1024)`` gives ``-0.0`` and ``from_si(-0.0)`` gives ``1024``
back, so every raw value survives a round trip.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Protocol

SIValue = float | int | bool | str

# Protocol-1 baud rates are 2 Mbps / (code + 1); a UART copes with a mismatch up to ~3 % (e-manual).
BAUDRATE_TOLERANCE = 0.03


class Converter(Protocol):
    """Turns one register's raw value into an SI value and back."""

    @property
    def unit(self) -> str:
        """The SI unit of ``to_si`` ("" when the value has no unit)."""
        ...

    def to_si(self, raw: int) -> SIValue:
        """Convert a raw register value (already sign-decoded) to its SI value."""
        ...

    def from_si(self, value: object) -> int:
        """Convert an SI value to the raw value; raises ValueError/TypeError when impossible."""
        ...

    def describe(self, min_raw: int, max_raw: int) -> str:
        """Describe the SI values matching raw values ``min_raw..max_raw`` (for error messages)."""
        ...


def _number(value: object) -> float:
    """Return ``value`` as a finite float, refusing bools, strings and NaN/inf."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise TypeError(f"expected a number, got {type(value).__name__}")
    number = float(value)
    if not math.isfinite(number):
        raise ValueError("expected a finite number")
    return number


def _fmt(value: float) -> str:
    return f"{value:.6g}"


@dataclass(frozen=True)
class Raw:
    """No conversion: the SI value is the raw integer (ids, modes, bit fields, ticks in ms...)."""

    unit: str = ""

    def to_si(self, raw: int) -> int:
        return int(raw)

    def from_si(self, value: object) -> int:
        number = _number(value)
        if not number.is_integer():
            raise ValueError("expected an integer")
        return int(number)

    def describe(self, min_raw: int, max_raw: int) -> str:
        return f"{min_raw} .. {max_raw}" + (f" {self.unit}" if self.unit else "")


@dataclass(frozen=True)
class Linear:
    """``si = (raw - offset_raw) * scale``: voltages, temperatures, delays, positions, gains..."""

    scale: float
    unit: str
    offset_raw: int = 0

    def to_si(self, raw: int) -> float:
        return (raw - self.offset_raw) * self.scale

    def from_si(self, value: object) -> int:
        return round(_number(value) / self.scale + self.offset_raw)

    def describe(self, min_raw: int, max_raw: int) -> str:
        low, high = sorted((self.to_si(min_raw), self.to_si(max_raw)))
        return f"{_fmt(low)} .. {_fmt(high)} {self.unit}".rstrip()


def position(range_deg: float, resolution: int) -> Linear:
    """Position in degrees, 0° at the middle of the range (AX raw 512 = 0°, MX/X raw 2048 = 0°).

    One tick is ``range_deg / resolution`` (AX: 300°/1024 ≈ 0.293°, MX/X: 360°/4096 ≈ 0.088°), so
    AX raw 0 → -150°, raw 1023 → +149.7°; MX raw 0 → -180°, raw 4095 → +179.9°.
    """
    return Linear(range_deg / resolution, "deg", resolution // 2)


def rpm(unit_rpm: float) -> Linear:
    """Unsigned or two's-complement speed with ``unit_rpm`` rev/min per tick, in deg/s."""
    return Linear(unit_rpm * 6.0, "deg/s")


@dataclass(frozen=True)
class DirectionBit:
    """Magnitude in bits 0-9, direction in bit 10 (set = CW = negative); e-manual speeds/loads.

    For ``moving_speed`` raw 0 means "as fast as possible, no speed control" (e-manual); its SI
    value is 0.0 all the same, so read a 0 goal speed as "unlimited", not "stopped".
    """

    scale: float
    unit: str

    def to_si(self, raw: int) -> float:
        magnitude = (raw & 0x3FF) * self.scale
        return -magnitude if raw & 0x400 else magnitude

    def from_si(self, value: object) -> int:
        number = _number(value)
        magnitude = round(abs(number) / self.scale)
        if magnitude > 0x3FF:
            raise ValueError("magnitude too large")
        return magnitude | 0x400 if math.copysign(1.0, number) < 0 else magnitude

    def describe(self, min_raw: int, max_raw: int) -> str:
        top = min(max_raw, 0x3FF) * self.scale
        low = -top if max_raw >= 0x400 else min_raw * self.scale
        return f"{_fmt(low)} .. {_fmt(top)} {self.unit}"


@dataclass(frozen=True)
class Boolean:
    """0/1 registers (torque_enable, led, moving...): a bool; writes take a bool or 0/1."""

    unit: str = ""

    def to_si(self, raw: int) -> bool:
        return bool(raw)

    def from_si(self, value: object) -> int:
        if isinstance(value, bool):
            return int(value)
        if isinstance(value, int):
            return value
        raise TypeError(f"expected a bool, got {type(value).__name__}")

    def describe(self, min_raw: int, max_raw: int) -> str:
        return "False/True (0/1)"


@dataclass(frozen=True)
class Choice:
    """Raw codes with names (XL-320 LED colours); writes take a name (any case) or the code.

    ``on`` names the value that means "on" (the XL-320 LED: ``"white"``, all three colours) and
    code 0 means "off": such a register switches like an on/off one (``Register.switched``).
    """

    names: tuple[tuple[int, str], ...]
    synonyms: tuple[tuple[str, int], ...] = ()
    mask: int = 0xFF
    unit: str = ""
    on: str | None = None

    def to_si(self, raw: int) -> str:
        code = raw & self.mask
        for known, name in self.names:
            if known == code:
                return name
        raise ValueError(f"unknown code {raw}")

    def from_si(self, value: object) -> int:
        if isinstance(value, str):
            wanted = value.strip().lower()
            for code, name in self.names:
                if name == wanted:
                    return code
            for name, code in self.synonyms:
                if name == wanted:
                    return code
            raise ValueError(f"unknown name {value!r}")
        if isinstance(value, int) and not isinstance(value, bool):
            return value
        raise TypeError(f"expected a name or an int, got {type(value).__name__}")

    def describe(self, min_raw: int, max_raw: int) -> str:
        return ", ".join(f"{name} ({code})" for code, name in self.names)


@dataclass(frozen=True)
class Baudrate:
    """Baud-rate code ⇄ bps for one model.

    ``table`` maps the e-manual's listed codes to *nominal* rates (what you give pyserial:
    protocol-1 code 34 → 57_600 although the servo really runs at 2M/35 = 57_142 bps). With
    ``clock_bps`` set (protocol 1), any other code gives ``round(clock_bps / (code + 1))``.
    ``from_si`` accepts the nominal rate, the exact rate, or anything within 3 % of a code's rate
    (the closest wins).
    """

    table: tuple[tuple[int, int], ...]
    clock_bps: int | None = None
    max_code: int = 0
    unit: str = "bps"
    _rates: tuple[tuple[int, int], ...] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        listed = dict(self.table)
        rates = dict(listed)
        if self.clock_bps is not None:
            for code in range(self.max_code + 1):
                rates.setdefault(code, round(self.clock_bps / (code + 1)))
        object.__setattr__(self, "_rates", tuple(sorted(rates.items())))

    def bps(self, code: int) -> int:
        """Return the (nominal) rate of ``code``; ValueError for a code the model does not have."""
        for known, rate in self._rates:
            if known == code:
                return rate
        raise ValueError(f"unknown baud-rate code {code}")

    def code(self, bps: float) -> int:
        """Return the code for ``bps`` (nominal, exact, or within 3 %); ValueError otherwise."""
        for code, nominal in self.table:
            if nominal == bps:
                return code
        for code, rate in self._rates:
            if rate == bps:
                return code
        close = [
            (abs(rate - bps), code)
            for code, rate in self._rates
            if abs(rate - bps) <= BAUDRATE_TOLERANCE * rate
        ]
        if not close:
            raise ValueError(f"no baud-rate code for {bps} bps")
        return min(close)[1]

    def to_si(self, raw: int) -> int:
        return self.bps(raw)

    def from_si(self, value: object) -> int:
        return self.code(_number(value))

    def describe(self, min_raw: int, max_raw: int) -> str:
        listed = sorted({rate for _, rate in self.table})
        return "one of " + ", ".join(str(rate) for rate in listed) + " bps"


# Shared converters.
VOLTAGE = Linear(0.1, "V")
TEMPERATURE = Linear(1.0, "°C")
RETURN_DELAY = Linear(2.0, "µs")
TORQUE_PERCENT = Linear(100 / 1023, "%")
LOAD_PERCENT = DirectionBit(0.1, "%")
BOOL = Boolean()
RAW = Raw()
MILLISECONDS = Raw("ms")


def gain(scale: float) -> Linear:
    """A PID gain exposed with its e-manual scaling (e.g. MX ``Kp = raw / 8`` → ``gain(1 / 8)``)."""
    return Linear(scale, "")
