"""Fault injection on the emulated line: corrupt or lost replies, extra delay, unplugged motors."""

from __future__ import annotations

import random
import threading
from collections.abc import Iterable

from poppy_core.models import ServoModel
from poppy_core.protocol import protocol_for


class FaultInjector:
    """Thread-safe fault knobs, reproducible through a seeded random generator.

    Args:
        seed: seed of the random generator deciding which replies are dropped or corrupted.
    """

    def __init__(self, seed: int = 0) -> None:
        self._lock = threading.Lock()
        self._rng = random.Random(seed)
        self._corrupt_rate = 0.0
        self._drop_rate = 0.0
        self._extra_delay_s = 0.0
        self._unplugged: set[int] = set()
        self.dropped_replies = 0
        self.corrupted_bytes = 0

    @staticmethod
    def _probability(value: float, name: str) -> float:
        if not 0.0 <= value <= 1.0:
            raise ValueError(f"{name} must be within [0, 1], got {value}")
        return float(value)

    @property
    def corrupt_rate(self) -> float:
        """Probability that any one reply byte gets one bit flipped."""
        return self._corrupt_rate

    @corrupt_rate.setter
    def corrupt_rate(self, value: float) -> None:
        with self._lock:
            self._corrupt_rate = self._probability(value, "corrupt_rate")

    @property
    def drop_rate(self) -> float:
        """Probability that a whole reply (one status packet) is lost."""
        return self._drop_rate

    @drop_rate.setter
    def drop_rate(self, value: float) -> None:
        with self._lock:
            self._drop_rate = self._probability(value, "drop_rate")

    @property
    def extra_delay_s(self) -> float:
        """Delay added before every reply, in seconds."""
        return self._extra_delay_s

    @extra_delay_s.setter
    def extra_delay_s(self, value: float) -> None:
        if value < 0:
            raise ValueError(f"extra_delay_s must be >= 0, got {value}")
        with self._lock:
            self._extra_delay_s = float(value)

    def reseed(self, seed: int) -> None:
        """Restart the random generator from ``seed``."""
        with self._lock:
            self._rng.seed(seed)

    def unplug(self, motor_id: int) -> None:
        """Disconnect a motor: it no longer hears nor answers anything."""
        with self._lock:
            self._unplugged.add(motor_id)

    def plug(self, motor_id: int) -> None:
        """Reconnect a motor unplugged with :meth:`unplug`."""
        with self._lock:
            self._unplugged.discard(motor_id)

    def is_unplugged(self, motor_id: int) -> bool:
        """Tell whether a motor (by its current id) is unplugged."""
        with self._lock:
            return motor_id in self._unplugged

    def filter_reply(self, data: bytes) -> bytes | None:
        """Apply drop and corruption to one reply.

        Args:
            data: the bytes of one status packet.

        Returns:
            None when the reply is dropped, otherwise the bytes, possibly with bits flipped.
        """
        with self._lock:
            if self._drop_rate and self._rng.random() < self._drop_rate:
                self.dropped_replies += 1
                return None
            if not self._corrupt_rate:
                return data
            out = bytearray(data)
            for i in range(len(out)):
                if self._rng.random() < self._corrupt_rate:
                    out[i] ^= 1 << self._rng.randrange(8)
                    self.corrupted_bytes += 1
            return bytes(out)


# e-manual (X-series, Hardware Error Status (70)).
_X_HARDWARE_BITS = {
    "input voltage": 0x01,
    "overheating": 0x04,
    "motor encoder": 0x08,
    "electrical shock": 0x10,
    "overload": 0x20,
}
# e-manual (XL-320, Hardware Error Status (50)).
_XL320_HARDWARE_BITS = {"overload": 0x01, "overheating": 0x02, "input voltage": 0x04}


def fault_bits(model: ServoModel, errors: Iterable[str]) -> int:
    """Bit mask of named hardware errors for ``model``.

    Args:
        model: the servo model (protocol 1 uses status error bits, protocol 2 the bits of the
            Hardware Error Status register).
        errors: names such as ``"overload"`` (case-insensitive, ``_`` accepted for spaces).

    Raises:
        ValueError: a name the model does not report.
    """
    # Protocol 1 names the faults in the status error byte (``status_fault_bits``); protocol 2
    # keeps them in the model's Hardware Error Status register.
    table = protocol_for(model.protocol).status_fault_bits
    if table is None:
        xl320 = model.name.upper().startswith("XL-320")
        table = _XL320_HARDWARE_BITS if xl320 else _X_HARDWARE_BITS
    bits = 0
    for name in errors:
        key = name.strip().lower().replace("_", " ")
        if key not in table:
            raise ValueError(f"{model.name} cannot report {name!r}; known: {', '.join(table)}")
        bits |= table[key]
    return bits


def shutdown_register_names() -> tuple[str, ...]:
    """Names of the register selecting which errors turn the torque off (e-manual: Shutdown)."""
    return ("shutdown", "alarm_shutdown")
