"""Blocking bus work for the TUI (no Textual here): shared ports, control tables, live samples."""

from __future__ import annotations

import logging
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, replace

from poppy_core.bus import DxlBus, Transport
from poppy_core.errors import PoppyError, RegisterError, SetupError
from poppy_core.models import Register, ServoModel, model_by_name

logger = logging.getLogger(__name__)

SIValue = float | int | bool | str
LIVE_REGISTERS = (
    "present_position",
    "present_speed",
    "present_load",
    "present_temperature",
    "present_voltage",
)


@dataclass(frozen=True)
class MotorRef:
    """Where one motor lives: port, rate, protocol, ID, and its model name (None: unknown)."""

    port: str
    baudrate: int
    protocol: int
    id: int
    model: str | None
    firmware: int | None = None

    @property
    def key(self) -> str:
        """A stable key for this motor (port, rate, protocol and ID)."""
        return f"{self.port}|{self.baudrate}|{self.protocol}|{self.id}"

    def servo_model(self) -> ServoModel:
        """The ``ServoModel`` of this motor.

        Raises:
            SetupError: the model is unknown to poppy.
        """
        if self.model is None:
            raise SetupError(f"motor {self.id} has a model poppy does not know")
        return model_by_name(self.model)

    def moved(self, *, id: int | None = None, baudrate: int | None = None) -> MotorRef:
        """The same motor after an ID or baud-rate change."""
        return replace(
            self,
            id=self.id if id is None else id,
            baudrate=self.baudrate if baudrate is None else baudrate,
        )


@dataclass(frozen=True)
class RegisterRow:
    """One control-table row as shown: the register and its SI value (None: unreadable)."""

    register: Register
    value: SIValue | None


@dataclass(frozen=True)
class LiveValues:
    """Present position (deg), speed (deg/s), load (%), temperature (°C), voltage (V)."""

    position_deg: float
    speed_dps: float
    load_percent: float
    temperature_c: float
    voltage_v: float

    def registers(self) -> dict[str, float]:
        """Register name (``LIVE_REGISTERS``) -> its value in this sample."""
        values = (
            self.position_deg,
            self.speed_dps,
            self.load_percent,
            self.temperature_c,
            self.voltage_v,
        )
        return dict(zip(LIVE_REGISTERS, values, strict=True))


class BusPool:
    """One open transport per port, shared by every operation, one operation at a time.

    A scan opens its own transport, so :meth:`exclusive` closes ours while it runs.
    """

    def __init__(self) -> None:
        self._guard = threading.Lock()
        self._locks: dict[str, threading.Lock] = {}
        self._transports: dict[str, Transport] = {}

    def _lock(self, port: str) -> threading.Lock:
        with self._guard:
            return self._locks.setdefault(port, threading.Lock())

    def _acquire(self, port: str, timeout_s: float) -> threading.Lock:
        lock = self._lock(port)
        if not lock.acquire(timeout=timeout_s):
            raise SetupError(f"{port} is busy (a scan or another operation is running)")
        return lock

    @contextmanager
    def bus(self, motor: MotorRef, timeout_s: float = 2.0) -> Iterator[DxlBus]:
        """Hold ``motor``'s port and yield a bus at its rate and protocol.

        Raises:
            SetupError: the port stays busy for ``timeout_s``.
            PortError: the port cannot be opened.
        """
        lock = self._acquire(motor.port, timeout_s)
        try:
            transport = self._transports.get(motor.port)
            if transport is None:
                transport = Transport(motor.port)
                self._transports[motor.port] = transport
            yield DxlBus(motor.port, motor.baudrate, motor.protocol, transport=transport)
        except PoppyError:
            self._drop(motor.port)
            raise
        finally:
            lock.release()

    @contextmanager
    def exclusive(self, port: str, timeout_s: float = 5.0) -> Iterator[None]:
        """Hold ``port`` with our transport closed (for a scan, which opens its own)."""
        lock = self._acquire(port, timeout_s)
        try:
            self._drop(port)
            yield
        finally:
            lock.release()

    def _drop(self, port: str) -> None:
        transport = self._transports.pop(port, None)
        if transport is not None:
            transport.close()

    def close(self) -> None:
        """Close every transport."""
        for port in list(self._transports):
            self._drop(port)


def read_table(bus: DxlBus, motor_id: int, model: ServoModel) -> list[RegisterRow]:
    """Read the whole control table in one transaction (one read per register as a fallback)."""
    registers = sorted(model.registers.values(), key=lambda reg: reg.address)
    try:
        data = bus.read(motor_id, 0, model.table_size)
    except PoppyError as exc:
        logger.debug("block read of motor %d failed (%s); reading one by one", motor_id, exc)
        return [RegisterRow(reg, _read_one(bus, motor_id, reg)) for reg in registers]
    rows = []
    for reg in registers:
        try:
            value: SIValue | None = reg.decode_si(data, start=0)
        except RegisterError:
            value = None
        rows.append(RegisterRow(reg, value))
    return rows


def _read_one(bus: DxlBus, motor_id: int, reg: Register, attempts: int = 2) -> SIValue | None:
    """One register, asked twice before it shows as unknown: the block read failed already, so
    the line is unreliable now (a busy machine's adapter, a noisy bus)."""
    for _ in range(attempts):
        try:
            return reg.decode_si(bus.read(motor_id, reg.address, reg.size))
        except PoppyError:
            continue
    return None


def read_live(bus: DxlBus, motor_id: int, model: ServoModel) -> LiveValues:
    """Read present position, speed, load, temperature and voltage in one transaction."""
    regs = [model.register(name) for name in LIVE_REGISTERS]
    start = min(reg.address for reg in regs)
    end = max(reg.address + reg.size for reg in regs)
    data = bus.read(motor_id, start, end - start)
    values = [float(reg.decode_si(data, start)) for reg in regs]
    return LiveValues(*values)


def parse_si(register: Register, text: str) -> SIValue:
    """Turn typed text into the SI value for ``register`` and check it with ``from_si``.

    Raises:
        RegisterError: the text is not a value this register accepts (the message says why).
    """
    value = register.parse(text)
    register.from_si(value)
    return value
