"""``MotorLink``: the robot side of one motor (register cache, pending writes, online state).

A ``Motor`` owns one and keeps it off the user's tab completion: only the sync loops
(``BusSync``), the goto runner, start-up, calibration and the ``Robot`` reach it, through
``link_of(motor)``. Values are kept in the motor frame and SI units. A value set
through the motor is checked against its register and stays *pending* until a write cycle takes
it (``take_pending``); reads from the servo arrive through ``update``. One reentrant lock per
motor (``MotorLink.lock``) guards all of it; the ``Motor`` takes the same lock when a change
spans several registers (compliance). The link names its motor and its goto runner by what it
uses of them (``Linked``, ``GotoTarget``, ``Runner``), so it imports neither ``motor`` nor ``goto``.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Iterable, Mapping
from typing import TYPE_CHECKING, Protocol, TypeVar

from poppy_core.errors import RegisterError, RobotClosedError
from poppy_core.models import ServoModel

if TYPE_CHECKING:
    from poppy_core.robot.goto_handle import GotoHandle

SIValue = float | int | bool | str

_Target = TypeVar("_Target", bound="GotoTarget")


def _nothing() -> None:
    """The default hook: nothing to do."""


class MotorLink:
    """Cached registers, pending writes and online state of one servo.

    Args:
        name: the motor's name (for errors).
        model: its servo model.
        runner: the goto runner its gotos go through (the robot's once attached).
        on_position: called (under ``lock``) after each present position read; the ``Motor``
            applies safe compliance there.
        set_goal: sets the goal from a user-frame angle (clamped to the limits) without
            cancelling a goto: what the goto runner calls.

    Attributes:
        lock: the motor's lock (reentrant).
        runner: see Args.
        online: False once the sync loop found the motor silent (it is then retried slowly).
        errors: failed reads so far.
        torque: True when the torque is (meant to be) on.
        compliant: True when the motor is meant to be free (torque off, but for safe compliance).
    """

    def __init__(
        self,
        name: str,
        model: ServoModel,
        runner: Runner,
        *,
        on_position: Callable[[], None] = _nothing,
        set_goal: Callable[[float], None],
    ) -> None:
        self.name = name
        self.model = model
        self.runner = runner
        self.lock = threading.RLock()
        self._on_position = on_position
        self._set_goal = set_goal
        self._values: dict[str, SIValue] = {}
        self._pending: dict[str, int] = {}
        self.compliant = True
        self.torque = False
        self.online = True
        self.errors = 0
        self._misses = 0
        self._closed = False

    # -- the cache -----------------------------------------------------------------------------

    def cached(self, name: str) -> SIValue | None:
        """The cached value of register ``name`` (motor frame SI), None if never read or set."""
        with self.lock:
            return self._values.get(name)

    def get(self, name: str, default: SIValue = 0.0) -> SIValue:
        """The cached value of register ``name``, ``default`` when unknown."""
        with self.lock:
            return self._values.get(name, default)

    def number(self, name: str) -> float:
        """The cached value of register ``name`` as a float (0.0 when unknown or not a number)."""
        value = self.get(name)
        return float(value) if isinstance(value, int | float) else 0.0

    def store(self, name: str, value: SIValue) -> None:
        """Check ``value`` against register ``name`` and mark it for the next write cycle.

        Raises:
            RegisterError: a read-only register or a value it cannot hold.
            RobotClosedError: the robot is closed.
        """
        if self._closed:
            raise RobotClosedError(f"{self.name}: the robot is closed, {name} cannot be written")
        register = self.model.register(name)
        if not register.writable:
            raise RegisterError(f"{self.name}: {name} is read-only", register=name, motor=self.name)
        try:
            raw = register.from_si(value)
        except RegisterError as exc:  # the model knows the register; name the motor too
            raise RegisterError(f"{self.name}: {exc}", register=name, motor=self.name) from None
        with self.lock:
            self._values[name] = value
            self._pending[name] = raw

    def set_torque(self, on: bool) -> None:
        """Mark the torque on or off for the next write cycle."""
        with self.lock:
            self.torque = on
            self.store("torque_enable", on)

    def set_goal(self, user_deg: float) -> None:
        """Set the goal position (user frame, clamped to the limits) without cancelling a goto."""
        self._set_goal(user_deg)

    def update(self, values: Mapping[str, object]) -> None:
        """Store values read from the servo (motor frame SI), then apply safe compliance."""
        with self.lock:
            for name, value in values.items():
                if isinstance(value, int | float | bool | str):
                    self._values[name] = value
            if "torque_enable" in values:
                self.torque = bool(values["torque_enable"])
                self.compliant = not self.torque
            if "present_position" in values:
                self._on_position()

    # -- the write cycle -------------------------------------------------------------------------

    def take_pending(self, names: Iterable[str]) -> dict[str, int]:
        """Remove and return the raw values waiting to be written among ``names``.

        A goal position waits while the torque is off: on protocol 1 servos writing it would
        switch the torque on.
        """
        with self.lock:
            out: dict[str, int] = {}
            for name in names:
                if name == "goal_position" and not self.torque:
                    continue
                if name in self._pending:
                    out[name] = self._pending.pop(name)
            return out

    def restore_pending(self, raw_values: Mapping[str, int]) -> None:
        """Put back values a failed write cycle took (unless newer ones were set since)."""
        with self.lock:
            for name, raw in raw_values.items():
                self._pending.setdefault(name, raw)

    def drop_pending(self) -> None:
        """Forget the values waiting to be written (the motors were let go: what was asked
        before must not be sent when they are taken back)."""
        with self.lock:
            self._pending.clear()

    def has_pending(self) -> bool:
        """True when some value waits to be written."""
        with self.lock:
            return bool(self._pending)

    def resend_state(self) -> None:
        """Mark the torque state (and goal) for writing again, e.g. after a motor came back."""
        with self.lock:
            for name in ("torque_enable", "goal_position"):
                value = self._values.get(name)
                if value is not None:
                    self.store(name, value)

    # -- online state --------------------------------------------------------------------------

    def mark_answered(self) -> bool:
        """Record a successful read; True when the motor just came back online."""
        with self.lock:
            self._misses = 0
            back = not self.online
            self.online = True
            return back

    def mark_offline(self) -> bool:
        """Mark the motor offline at once (its bus was lost, or it is missing at start-up);
        True when it was online."""
        with self.lock:
            was_online = self.online
            self.online = False
            return was_online

    def mark_missed(self, offline_after: int) -> bool:
        """Record a failed read; True when the motor just went offline."""
        with self.lock:
            self.errors += 1
            self._misses += 1
            if self.online and self._misses >= offline_after:
                self.online = False
                return True
            return False

    def mark_closed(self) -> None:
        """The robot is closed: later writes raise ``RobotClosedError`` (reads keep the last
        values)."""
        self._closed = True


class Linked(Protocol):
    """What holds a ``MotorLink`` (a ``Motor``): all ``link_of`` needs of it."""

    @property
    def _link(self) -> MotorLink:
        """The motor's link."""
        ...


class GotoTarget(Linked, Protocol):
    """What the goto runner reads and sets of a motor it moves (a ``Motor`` gives it); its goals
    go through the motor's link (``link_of``)."""

    name: str
    model: ServoModel
    wheel_mode: bool

    @property
    def goto_behavior(self) -> str:
        """The control of gotos that name none."""
        ...

    @property
    def present_position(self) -> float:
        """Position in degrees (user frame), as last read."""
        ...

    @property
    def angle_limit(self) -> tuple[float, float]:
        """(min, max) in degrees, user frame."""
        ...

    @property
    def moving_speed(self) -> float:
        """Speed limit toward the goal in deg/s."""
        ...

    @moving_speed.setter
    def moving_speed(self, value: float) -> None: ...


class Runner(Protocol):
    """What a link's motor and its group need of the goto runner they share (a ``GotoRunner``)."""

    def start(
        self, targets: Mapping[_Target, float], duration_s: float, control: str | None
    ) -> GotoHandle:
        """Start moving each motor to its target (degrees, user frame) in ``duration_s``."""
        ...

    def goals(self) -> dict[str, float]:
        """Each motor moving under a goto -> the goal it goes to (degrees, user frame)."""
        ...

    def cancel(self, motor: GotoTarget) -> None:
        """Stop the goto of ``motor`` where it is."""
        ...


def link_of(motor: Linked) -> MotorLink:
    """The robot side of ``motor``: its cache, pending writes and online state (for the sync
    loops, the goto runner, start-up and the ``Robot``; a user script never needs it)."""
    return motor._link
