"""``MotorCache``: a motor's register cache shared with the sync loops, plus its gains and LED.

Values are kept in the motor frame and SI units. A set value is checked against its register and
stays *pending* until a write cycle takes it; reads from the servo arrive through ``update``.
"""

from __future__ import annotations

import threading
from collections.abc import Iterable, Mapping

from poppy_core.errors import RegisterError
from poppy_core.models import ServoModel
from poppy_core.robot import registers as regs

SIValue = float | int | bool | str


class MotorCache:
    """Cached registers of one servo (``Motor`` builds the user-frame API on it).

    Attributes:
        name: the motor's name.
        model: its servo model.
        online: False once the sync loop found it silent (it is then retried at a low rate).
        errors: failed reads so far.
    """

    def __init__(self, name: str, model: ServoModel) -> None:
        self.name = name
        self.model = model
        self._lock = threading.RLock()
        self._values: dict[str, SIValue] = {}
        self._pending: dict[str, int] = {}
        self._compliant = True
        self._torque = False
        self.online = True
        self.errors = 0
        self._misses = 0

    def _apply_safe_compliance(self) -> None:
        """Hook run after each position update (``Motor`` implements safe compliance)."""

    def _get(self, name: str, default: SIValue = 0.0) -> SIValue:
        with self._lock:
            return self._values.get(name, default)

    def _number(self, name: str) -> float:
        value = self._get(name)
        return float(value) if isinstance(value, int | float) else 0.0

    def cached(self, name: str) -> SIValue | None:
        """The cached value of register ``name`` (motor frame SI), None if never read or set."""
        with self._lock:
            return self._values.get(name)

    def cached_number(self, name: str) -> float:
        """``cached(name)`` as a float (0.0 when unknown or not a number)."""
        return self._number(name)

    def _store(self, name: str, value: SIValue) -> None:
        """Check ``value`` against register ``name`` and mark it for the next write cycle."""
        register = self.model.register(name)
        if not register.writable:
            raise RegisterError(f"{self.name}: {name} is read-only", register=name, motor=self.name)
        try:
            raw = register.from_si(value)
        except RegisterError as exc:  # the model knows the register; name the motor too
            raise RegisterError(f"{self.name}: {exc}", register=name, motor=self.name) from None
        with self._lock:
            self._values[name] = value
            self._pending[name] = raw

    def take_pending(self, names: Iterable[str]) -> dict[str, int]:
        """Remove and return the raw values waiting to be written among ``names``.

        A goal position waits while the torque is off: on protocol 1 servos writing it would
        switch the torque on.
        """
        with self._lock:
            out: dict[str, int] = {}
            for name in names:
                if name == "goal_position" and not self._torque:
                    continue
                if name in self._pending:
                    out[name] = self._pending.pop(name)
            return out

    def restore_pending(self, raw_values: Mapping[str, int]) -> None:
        """Put back values a failed write cycle took (unless newer ones were set since)."""
        with self._lock:
            for name, raw in raw_values.items():
                self._pending.setdefault(name, raw)

    def has_pending(self) -> bool:
        """True when some value waits to be written."""
        with self._lock:
            return bool(self._pending)

    def update(self, values: Mapping[str, object]) -> None:
        """Store values read from the servo (motor frame SI), then apply safe compliance."""
        with self._lock:
            for name, value in values.items():
                if isinstance(value, int | float | bool | str):
                    self._values[name] = value
            if "torque_enable" in values:
                self._torque = bool(values["torque_enable"])
                self._compliant = not self._torque
            if "present_position" in values:
                self._apply_safe_compliance()

    def mark_answered(self) -> bool:
        """Record a successful read; True when the motor just came back online."""
        with self._lock:
            self._misses = 0
            back = not self.online
            self.online = True
            return back

    def resend_state(self) -> None:
        """Mark the torque state (and goal) for writing again, e.g. after a motor came back."""
        with self._lock:
            for name in ("torque_enable", "goal_position"):
                value = self._values.get(name)
                if value is not None:
                    self._store(name, value)

    def mark_offline(self) -> bool:
        """Mark the motor offline at once (its bus was lost); True when it was online."""
        with self._lock:
            was_online = self.online
            self.online = False
            return was_online

    def mark_missed(self, offline_after: int) -> bool:
        """Record a failed read; True when the motor just went offline."""
        with self._lock:
            self.errors += 1
            self._misses += 1
            if self.online and self._misses >= offline_after:
                self.online = False
                return True
            return False

    # -- gains and LED ---------------------------------------------------------------------

    @property
    def pid(self) -> tuple[float, float, float]:
        """(P, I, D) gains, in the model's e-manual scaling (MX, XL-320, X-series)."""
        names = self._pid_names()
        return (self._number(names[0]), self._number(names[1]), self._number(names[2]))

    @pid.setter
    def pid(self, gains: tuple[float, float, float]) -> None:
        for name, value in zip(self._pid_names(), gains, strict=True):
            self._store(name, float(value))

    def _pid_names(self) -> tuple[str, str, str]:
        names = regs.pid_names(self.model)
        if names is None:
            raise RegisterError(
                f"{self.name}: {self.model.name} has no PID gains (use compliance_margin/slope)",
                register="pid", motor=self.name,
            )
        return names

    @property
    def compliance_margin(self) -> tuple[int, int]:
        """(CW, CCW) compliance margins (AX); set one number for both or a pair."""
        return self._pair(regs.AX_MARGINS)

    @compliance_margin.setter
    def compliance_margin(self, value: int | tuple[int, int]) -> None:
        self._set_pair(regs.AX_MARGINS, value)

    @property
    def compliance_slope(self) -> tuple[int, int]:
        """(CW, CCW) compliance slopes (AX); set one number for both or a pair."""
        return self._pair(regs.AX_SLOPES)

    @compliance_slope.setter
    def compliance_slope(self, value: int | tuple[int, int]) -> None:
        self._set_pair(regs.AX_SLOPES, value)

    def _pair(self, names: tuple[str, str]) -> tuple[int, int]:
        self._need_slopes()
        return int(self._number(names[0])), int(self._number(names[1]))

    def _set_pair(self, names: tuple[str, str], value: int | tuple[int, int]) -> None:
        self._need_slopes()
        pair = (value, value) if isinstance(value, int) else value
        for name, item in zip(names, pair, strict=True):
            self._store(name, item)

    def _need_slopes(self) -> None:
        if not regs.has_compliance_slopes(self.model):
            raise RegisterError(
                f"{self.name}: {self.model.name} has no compliance margin/slope (use pid)",
                register="compliance_margin", motor=self.name,
            )

    @property
    def led(self) -> SIValue:
        """LED state: a bool, or a colour name on the XL-320."""
        return self._get("led", False)

    @led.setter
    def led(self, value: SIValue) -> None:
        self._store("led", value)
