"""Small records returned by the bus layer: ping results, counters, scan findings, setup results."""

from __future__ import annotations

from dataclasses import dataclass, field

from poppy_core.models import ServoModel


@dataclass(frozen=True)
class PingResult:
    """A motor that answered a ping.

    Attributes:
        id: the motor's ID.
        model_number: the model number it reports (None if it could not be read, protocol 1).
        firmware: its firmware version (None if it could not be read).
        model: the matching ``ServoModel``, None for a model number poppy does not know.
    """

    id: int
    model_number: int | None
    firmware: int | None
    model: ServoModel | None

    @property
    def model_name(self) -> str | None:
        """The model's name (``"MX-28"``), None when unknown."""
        return None if self.model is None else self.model.name


@dataclass
class BusStats:
    """Counters of one bus since it was opened.

    Attributes:
        transactions: transactions started (a retry is part of the same transaction).
        timeouts: attempts that ended without the expected reply.
        corrupt_packets: status packets dropped for a bad checksum/CRC or shape.
        retries: attempts repeated after a timeout or a corrupt reply.
        motor_errors: status packets whose error bits made a transaction fail.
        alarms: status packets carrying only alarm bits (overload, overheating, input voltage,
            hardware alert); the data was still used.
    """

    transactions: int = 0
    timeouts: int = 0
    corrupt_packets: int = 0
    retries: int = 0
    motor_errors: int = 0
    alarms: int = 0

    def as_dict(self) -> dict[str, int]:
        """The counters as a plain dict (for ``--json``)."""
        return {
            "transactions": self.transactions,
            "timeouts": self.timeouts,
            "corrupt_packets": self.corrupt_packets,
            "retries": self.retries,
            "motor_errors": self.motor_errors,
            "alarms": self.alarms,
        }


@dataclass(frozen=True)
class FoundMotor:
    """A motor found by ``scan``.

    Attributes:
        port: where it is.
        baudrate: the rate it answered at.
        protocol: the protocol it answered in.
        id: its ID.
        model_number: the model number it reports (None if it could not be read).
        model: the model's name, None for a model number poppy does not know.
        firmware: its firmware version (None if it could not be read).
    """

    port: str
    baudrate: int
    protocol: int
    id: int
    model_number: int | None
    model: str | None
    firmware: int | None


@dataclass(frozen=True)
class ScanProgress:
    """Where a scan is.

    Attributes:
        port: port being scanned.
        baudrate: rate being scanned.
        protocol: protocol being scanned.
        step: what is being done (``"broadcast ping"``, ``"ping"``).
        id: the ID just pinged (None for a broadcast).
        done: pings done over the whole scan.
        total: pings the whole scan may do (an upper bound: a trusted broadcast skips some).
        found: motors found so far.
    """

    port: str
    baudrate: int
    protocol: int
    step: str
    id: int | None
    done: int
    total: int
    found: int

    @property
    def fraction(self) -> float:
        """Progress between 0 and 1."""
        return 1.0 if self.total <= 0 else min(1.0, self.done / self.total)


@dataclass
class SetupResult:
    """What a setup operation did.

    Attributes:
        operation: ``"change_id"``, ``"change_baudrate"``, ``"reset_motor"``...
        port: the bus's port.
        motor_id: the motor's ID when the operation ended.
        baudrate: the rate the motor answers at when the operation ended.
        protocol: the bus protocol.
        changes: register name -> (old, new) values written (SI units), old None if unknown.
        notes: readable remarks (steps taken, things to know).
        verified: True when the result was checked by reading the motor back.
    """

    operation: str
    port: str
    motor_id: int
    baudrate: int
    protocol: int
    changes: dict[str, tuple[object, object]] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)
    verified: bool = False
