"""``PrimitiveManager``: combines the requests of running primitives into real motor writes.

One manager per robot (``primitive_manager(robot)``), created on first use and closed with the
robot. Its thread starts with the first running primitive and ends when none is left; at
``freq`` Hz (drift-free) it gathers every primitive's requests per motor and register, combines
numeric ones with ``filter`` (mean by default, ``"sum"`` or any function of a list of floats) and
lets the most recently started primitive win on on/off registers (``compliant``, ``led``).
A primitive whose requests cannot be applied (a motor the robot does not have) is stopped as
failed, one WARNING line; the others and the manager go on. A combination that raises is the
thread's ``schedule.Ticker``'s: logged once, counted in ``errors``, retried with backoff.
"""

from __future__ import annotations

import logging
import math
import statistics
import threading
import time
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

from poppy_core import checks
from poppy_core.errors import ArgumentError, ConfigError, RobotClosedError
from poppy_core.motion.sandbox import NUMERIC_REGISTERS
from poppy_core.robot.robot_pypot import MANAGER_KEY
from poppy_core.schedule import RateMeter, Worker

if TYPE_CHECKING:
    from poppy_core.motion.primitive import Primitive
    from poppy_core.robot import Robot

logger = logging.getLogger(__name__)

Filter = Callable[[Sequence[float]], float]
FILTERS: dict[str, Filter] = {"mean": statistics.fmean, "sum": math.fsum}
"""Named filters: ``"mean"`` (pypot's default) and ``"sum"``."""
DEFAULT_FREQ_HZ = 50.0


def _resolve_filter(value: str | Filter) -> Filter:
    if isinstance(value, str):
        try:
            return FILTERS[value]
        except KeyError:
            known = ", ".join(FILTERS)
            raise ArgumentError(
                f"unknown filter {value!r} (filters: {known}, or a function)", field="filter"
            ) from None
    if not callable(value):
        raise ArgumentError(f"filter must be a name or a function, not {value!r}", field="filter")
    return value


class PrimitiveManager:
    """Applies the combined requests of the running primitives to the real motors.

    Args:
        robot: the robot whose motors receive the combined values.
        freq: combinations per second.
        filter: ``"mean"``, ``"sum"`` or a function combining a list of floats.
    """

    def __init__(
        self, robot: Robot, freq: float = DEFAULT_FREQ_HZ, filter: str | Filter = "mean"
    ) -> None:
        self.freq = checks.rate(freq, "manager frequency")
        self._robot = robot
        self._filter = _resolve_filter(filter)
        self._lock = threading.RLock()
        self._primitives: list[Primitive] = []
        self._thread: Worker | None = None  # one per run: it ends when no primitive is left
        self._closed = False
        self._applied: dict[tuple[str, str], Any] = {}
        self._meter = RateMeter()
        self.errors = 0
        self.last_error: str | None = None
        self._refused: set[tuple[str, str]] = set()  # writes failing now: logged once each

    def __repr__(self) -> str:
        return f"<PrimitiveManager {self.freq:g} Hz primitives={self._primitives}>"

    @property
    def filter(self) -> Filter:
        """The function combining numeric requests; set a name (``"sum"``) or a function."""
        return self._filter

    @filter.setter
    def filter(self, value: str | Filter) -> None:
        self._filter = _resolve_filter(value)

    @property
    def primitives(self) -> list[Primitive]:
        """The primitives whose requests are combined (running or paused), oldest first."""
        with self._lock:
            return list(self._primitives)

    @property
    def running(self) -> bool:
        """True while the manager's thread runs."""
        thread = self._thread
        return thread is not None and thread.running

    @property
    def rate_hz(self) -> float:
        """Measured combination rate."""
        return self._meter.rate_hz

    # -- membership --------------------------------------------------------------------------

    def add(self, primitive: Primitive) -> None:
        """Combine ``primitive``'s requests from now on (``start()`` calls it).

        Raises:
            RobotClosedError: the manager (its robot) is closed.
        """
        with self._lock:
            if self._closed:
                raise RobotClosedError("the robot is closed: primitives cannot start any more")
            if primitive not in self._primitives:
                self._primitives.append(primitive)
            if self._thread is None:
                self._thread = Worker.periodic(
                    "primitive manager",
                    self.freq,
                    self._tick,
                    on_failure=lambda exc: self._note_error(f"{type(exc).__name__}: {exc}"),
                    on_exit=self._ended,
                )
                self._thread.start()

    def remove(self, primitive: Primitive) -> None:
        """Stop combining ``primitive`` after applying its last requests (its thread calls it)."""
        with self._lock:
            if primitive in self._primitives:
                self.update()  # may reject it (a request it cannot have applied)
            if primitive in self._primitives:
                self._primitives.remove(primitive)

    # -- combining ---------------------------------------------------------------------------

    def combine(self, now: float | None = None) -> dict[str, dict[str, Any]]:
        """Motor name -> register -> the combined value of every primitive's request.

        A primitive whose requests cannot be had or name a motor the robot does not have is
        stopped as failed (``Primitive.fail``) and left out.
        """
        gathered: dict[str, dict[str, list[Any]]] = {}
        for primitive in self.primitives:
            try:
                requests = primitive.robot.requests(now)
                for motor in requests:
                    self._robot.motor(motor)  # UnknownMotorError: not this robot's motor
            except Exception as exc:
                self._reject(primitive, exc)
                continue
            for motor, requested in requests.items():
                per_motor = gathered.setdefault(motor, {})
                for register, value in requested.items():
                    per_motor.setdefault(register, []).append(value)
        out: dict[str, dict[str, Any]] = {}
        for motor, registers in gathered.items():
            for register, values in registers.items():
                if register in NUMERIC_REGISTERS:
                    value = self._filter([float(v) for v in values])
                    if not isinstance(value, int | float) or not math.isfinite(value):
                        self._note_error(f"filter gave {value!r} for {motor}.{register}")
                        continue
                    out.setdefault(motor, {})[register] = float(value)
                else:
                    out.setdefault(motor, {})[register] = values[-1]
        return out

    def update(self) -> None:
        """Combine the requests once and write what changed to the real motors."""
        with self._lock:
            try:
                combined = self.combine(time.monotonic())
            except Exception as exc:
                logger.exception("primitive manager: combining the requests failed")
                self._note_error(f"{type(exc).__name__}: {exc}")
                return
            for motor_name, registers in combined.items():
                motor = self._robot.motor(motor_name)
                for register, value in registers.items():
                    key = (motor_name, register)
                    if self._applied.get(key) == value:
                        continue
                    try:
                        setattr(motor, register, value)
                    except Exception as exc:
                        if key not in self._refused:  # once until it is taken again
                            self._refused.add(key)
                            logger.warning(
                                "primitive manager: %s.%s = %r refused: %s: %s",
                                motor_name,
                                register,
                                value,
                                type(exc).__name__,
                                exc,
                            )
                        self._note_error(f"{motor_name}.{register}: {exc}")
                        continue
                    self._refused.discard(key)
                    self._applied[key] = value

    def _reject(self, primitive: Primitive, exc: Exception) -> None:
        """Stop ``primitive`` as failed (its requests cannot be applied); the others go on."""
        with self._lock:
            if primitive in self._primitives:
                self._primitives.remove(primitive)
        self._note_error(f"{primitive.name}: {type(exc).__name__}: {exc}")
        primitive.fail(exc)

    def _note_error(self, message: str) -> None:
        self.errors += 1
        self.last_error = message

    def _tick(self, now: float) -> bool:
        """One combination; False (the thread ends) once no primitive is left."""
        with self._lock:
            if not self._primitives or self._closed:
                self._ended()
                return False
            self.update()
        self._meter.tick(now)
        return True

    def _ended(self) -> None:
        """The thread is ending (no primitive left, closed, or stopped): the next ``add``
        starts another."""
        with self._lock:
            if self._thread is not None and self._thread.is_current():
                self._thread = None
                self._applied.clear()

    # -- lifetime ----------------------------------------------------------------------------

    def close(self) -> None:
        """Stop every primitive, then the thread (the robot's ``close`` calls it)."""
        for primitive in self.primitives:
            primitive.halt(wait=True)
        with self._lock:
            self._closed = True
            self._primitives.clear()
            thread = self._thread
        if thread is not None:
            thread.close(2.0)


# -- one manager per robot ------------------------------------------------------------------------


def primitive_manager(robot: Robot) -> PrimitiveManager:
    """The robot's manager, created on first use (its thread only runs with primitives)."""
    existing = robot.extensions.get(MANAGER_KEY)
    if isinstance(existing, PrimitiveManager):
        return existing
    manager = PrimitiveManager(robot)
    chosen = robot.extensions.setdefault(MANAGER_KEY, manager)
    if chosen is manager:
        robot.on_close(manager.close)
    if not isinstance(chosen, PrimitiveManager):
        raise ConfigError(f"robot.extensions[{MANAGER_KEY!r}] is not a PrimitiveManager")
    return chosen
