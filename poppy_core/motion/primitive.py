"""``Primitive``: a restartable behaviour running in its own thread (``LoopPrimitive``, in
``loop_primitive``, paces one).

A primitive acts on a sandboxed view of the robot (``self.robot``, see ``sandbox``): its writes
are requests that the robot's ``PrimitiveManager`` combines with those of the other running
primitives. A primitive whose code raises is stopped, its traceback logged once at WARNING and
kept in ``error``; ``state`` then reads ``"failed"``, and whoever waits on it (``wait_to_stop``,
``stop``) gets a ``PrimitiveError`` raised from the original exception.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any, ClassVar

from poppy_core.errors import PrimitiveError
from poppy_core.motion import primitive_access
from poppy_core.motion.manager import PrimitiveManager, primitive_manager
from poppy_core.motion.primitive_failure import PrimitiveFailure, State
from poppy_core.motion.sandbox import MockupMotor, MockupRobot
from poppy_core.schedule import Gate, Worker

if TYPE_CHECKING:
    from poppy_core.robot import Motor, Robot

__all__ = ["JOIN_TIMEOUT_S", "Primitive", "PrimitiveFailure", "State"]

logger = logging.getLogger(__name__)

JOIN_TIMEOUT_S = 5.0


def _snake_case(name: str) -> str:
    return "".join(f"_{c.lower()}" if c.isupper() and i else c.lower() for i, c in enumerate(name))


class Primitive:
    """A behaviour in its own thread: ``setup()``, ``run()``, ``teardown()``; restartable.

    Subclass it and write ``run`` (check ``should_stop()``; use ``sleep()`` to wait). Writes to
    ``self.robot`` are requests combined by the manager; reads reach the real robot.

    Attributes:
        properties: names ``get_property``/``set_property`` expose (e.g. to the REST server).
        methods: names ``call_method`` may call.
        real_robot: the robot itself (writing to it bypasses the manager).
        robot: the sandboxed view this primitive acts on.
        error: why the last run failed, None otherwise.

    Args:
        robot: the robot to act on.
    """

    properties: ClassVar[Sequence[str]] = ()
    methods: ClassVar[Sequence[str]] = ("start", "stop", "pause", "resume")

    def __init__(self, robot: Robot) -> None:
        self.real_robot = robot
        self._stop_event = threading.Event()
        self._resume_event = threading.Event()
        self._resume_event.set()
        self._started_event = threading.Event()
        self.robot = MockupRobot(robot, self._stop_event)
        self._manager: PrimitiveManager = primitive_manager(robot)
        self._worker: Worker | None = None
        self._gate: Gate | None = None
        self._lifecycle = threading.Lock()
        self._state: State = "idle"
        self.error: PrimitiveFailure | None = None
        self._exception: BaseException | None = None
        self._t0: float | None = None
        self._origin: float | None = None
        self._paused_at: float | None = None
        self._paused_s = 0.0
        self._ended_at: float | None = None

    def __repr__(self) -> str:
        return f"<{type(self).__name__} {self.state}>"

    # -- to override -------------------------------------------------------------------------

    def setup(self) -> None:
        """Called in the primitive's thread before ``run`` at each (re)start."""

    def run(self) -> None:
        """The behaviour; return to finish. Long runs must check ``should_stop()``."""

    def teardown(self) -> None:
        """Called in the primitive's thread after ``run`` (also after a failure)."""

    # -- lifecycle ---------------------------------------------------------------------------

    def start(self, *, gate: Gate | None = None) -> None:
        """Start the primitive, or restart it (a running one is stopped first).

        With a ``gate``, the start is armed: everything is made now (its thread too), and
        ``setup`` and ``run`` begin when the gate opens; a stop before that cancels the gate and
        the primitive ends without having run. A gate with a start time (``Gate.at``) is the
        time origin: ``elapsed_time`` counts from it (see ``shared_start``), whenever the
        thread wakes.

        Raises:
            RobotClosedError: the robot is closed.
            RuntimeError: called from the primitive's own thread.
        """
        if self._worker is not None and self._worker.is_current():
            raise RuntimeError("a primitive cannot restart itself from its own thread")
        with self._lifecycle:
            if self.is_alive():
                self._stop_locked(wait=True)
            self.robot.clear()
            self._manager.add(self)  # raises when the robot is closed
            self._stop_event.clear()
            self._resume_event.set()
            self.error = None
            self._exception = None
            self._origin = gate.at if gate is not None else None
            self._t0 = time.monotonic() if self._origin is None else self._origin
            self._paused_s = 0.0
            self._paused_at = None
            self._ended_at = None
            self._state = "running"
            # One worker per run (the last one may still be finishing); ``_main`` catches the
            # run's exceptions itself: a primitive's failure is its own story (see ``error``).
            self._gate = gate
            self._worker = Worker(f"primitive {type(self).__name__}", lambda _: self._main(gate))
            self._worker.start()
            self._started_event.set()
        logger.info("%s started", type(self).__name__)

    def stop(self, wait: bool = True) -> None:
        """Ask the primitive to stop; with ``wait``, return once its thread ended.

        Raises:
            PrimitiveError: with ``wait``, the primitive's thread died (from its exception).
        """
        self.halt(wait)
        if wait:
            self.raise_failure()

    def halt(self, wait: bool = True) -> None:
        """Stop it as ``stop`` does, without raising its failure (supervisors read ``error``)."""
        with self._lifecycle:
            self._stop_locked(wait)

    def raise_failure(self) -> None:
        """Raise a ``PrimitiveError`` if the last run died (nothing when it ended well).

        Raises:
            PrimitiveError: naming the primitive and its exception, raised from that exception.
        """
        failure, exception = self.error, self._exception
        if failure is None:
            return
        error = PrimitiveError(
            f"primitive {self.name} died: {failure.one_line} (its traceback is in the log and in "
            "its .error)",
            primitive=self.name,
            failure=failure.one_line,
        )
        raise error from exception

    def _stop_locked(self, wait: bool) -> None:
        if self._gate is not None:
            self._gate.cancel()  # an armed start that has not fired never will
        self._stop_event.set()
        self._resume_event.set()
        worker = self._worker
        if (
            wait
            and worker is not None
            and not worker.is_current()
            and not worker.wait(JOIN_TIMEOUT_S)
        ):
            logger.warning("%s did not stop within %s s", type(self).__name__, JOIN_TIMEOUT_S)

    def pause(self) -> None:
        """Ask the primitive to pause (``should_pause()`` turns True); its requests stay."""
        if self._state == "running":
            self._resume_event.clear()
            # armed with a shared start: a pause before it takes nothing off the elapsed time
            self._paused_at = max(time.monotonic(), self._t0 or 0.0)
            self._state = "paused"
            logger.info("%s paused", type(self).__name__)

    def resume(self) -> None:
        """Let a paused primitive go on."""
        if self._state == "paused":
            if self._paused_at is not None:
                self._paused_s += max(0.0, time.monotonic() - self._paused_at)
            self._paused_at = None
            self._state = "running"
            self._resume_event.set()
            logger.info("%s resumed", type(self).__name__)

    def _main(self, gate: Gate | None = None) -> None:
        name = type(self).__name__
        if gate is not None and not gate.wait():
            self._end_armed()
            return
        if gate is not None and gate.at is None:
            self._t0 = time.monotonic()  # it began now, not when it was armed
        try:
            self.setup()
            if not self._stop_event.is_set():
                self.run()
        except Exception as exc:
            self._fail(exc)
        finally:
            try:
                self.teardown()
            except Exception as exc:
                if self.error is None:
                    self._fail(exc)
                else:
                    logger.exception("%s: teardown failed too", name)
            try:
                self._manager.remove(self)
            finally:
                self._ended_at = time.monotonic()
                if self._paused_at is not None:
                    self._paused_s += max(0.0, self._ended_at - self._paused_at)
                    self._paused_at = None
                if self._state != "failed":
                    self._state = "stopped"
                    logger.info("%s stopped", name)

    def _end_armed(self) -> None:
        """An armed start called off before its gate opened: it ends without having run."""
        try:
            self._manager.remove(self)
        finally:
            self._ended_at = time.monotonic()
            self._state = "stopped"
            logger.info("%s: its start was called off before its start time", type(self).__name__)

    def _fail(self, exc: BaseException) -> None:
        self.error = PrimitiveFailure.of(exc)
        text = self.error.traceback
        self._exception = exc
        self._state = "failed"
        self._stop_event.set()
        logger.warning("primitive %s died:\n%s", self.name, text.rstrip())

    def fail(self, exc: Exception) -> None:
        """Stop it as failed because of ``exc``, found outside its thread (its manager: a request
        for a motor the robot does not have); one WARNING line, ``state`` ``"failed"``, ``error``
        kept, and ``stop``/``wait_to_stop`` raise ``PrimitiveError`` as after a death."""
        self.error = PrimitiveFailure.of(exc)
        self._exception = exc
        self._state = "failed"
        self._stop_event.set()
        self._resume_event.set()
        logger.warning("primitive %s stopped by its manager: %s", self.name, self.error.one_line)

    # -- state -------------------------------------------------------------------------------

    @property
    def state(self) -> State:
        """``"idle"`` (never started), ``"running"``, ``"paused"``, ``"stopped"`` or ``"failed"``.

        A failed primitive keeps its ``error`` until it is started again.
        """
        return self._state

    @property
    def name(self) -> str:
        """The name it is attached under (``robot.<name>``), else its class name in snake case."""
        given = self.__dict__.get("_name")
        return given if given else _snake_case(type(self).__name__)

    @name.setter
    def name(self, value: str) -> None:
        self.__dict__["_name"] = str(value)

    @property
    def running(self) -> bool:
        """True from ``start()`` until it is asked to stop or ends (also when paused; pypot's)."""
        return self.is_alive() and not self.should_stop()

    @property
    def started(self) -> bool:
        """True once it was started (pypot's)."""
        return self._started_event.is_set()

    def wait_to_start(self, timeout_s: float | None = None) -> bool:
        """Block until it was started (by another thread); False when ``timeout_s`` ran out."""
        return self._started_event.wait(timeout_s)

    def is_alive(self) -> bool:
        """True while the thread runs (also when paused)."""
        worker = self._worker
        return worker is not None and worker.running

    def should_stop(self) -> bool:
        """True once ``stop()`` was asked: ``run`` should return."""
        return self._stop_event.is_set()

    def should_pause(self) -> bool:
        """True while paused: ``run`` should call ``wait_to_resume()``."""
        return not self._resume_event.is_set()

    def wait_to_resume(self, timeout_s: float | None = None) -> bool:
        """Block while paused; False when ``timeout_s`` ran out first."""
        return self._resume_event.wait(timeout_s)

    def wait_to_stop(self, timeout_s: float | None = None) -> bool:
        """Block until the thread ended; False when ``timeout_s`` ran out first.

        Raises:
            PrimitiveError: the primitive's thread died (raised from its exception).
        """
        worker = self._worker
        if worker is None or worker.is_current():
            return not self.is_alive()
        if not worker.wait(timeout_s):
            return False
        self.raise_failure()
        return True

    def sleep(self, seconds: float) -> bool:
        """Wait ``seconds`` unless stopped first; True when the primitive should stop."""
        return self._stop_event.wait(max(0.0, seconds))

    @property
    def shared_start(self) -> float | None:
        """The shared start this run counts its time from: its gate's ``at`` (on the
        ``time.monotonic()`` clock), or None (started at once, or through a gate without one).

        A fleet's robots started together stay in phase: a thread that woke late computes what
        is due now (``elapsed_time`` counts from here, ``LoopPrimitive`` updates on the grid
        ``shared_start + k * period``) instead of playing from the beginning, late.
        """
        return self._origin

    @property
    def elapsed_time(self) -> float:
        """Seconds since the (re)start, pauses left out; frozen once stopped; 0 before.

        The start is ``shared_start`` when there is one (a thread that woke late reads the time
        since then), else when it was started (or, armed, when its gate opened).
        """
        if self._t0 is None:
            return 0.0
        end = self._ended_at if self._ended_at is not None else time.monotonic()
        paused = self._paused_s
        if self._paused_at is not None:
            paused += max(0.0, end - self._paused_at)
        return max(0.0, end - self._t0 - paused)

    def get_mockup_motor(self, motor: Motor | MockupMotor | str) -> MockupMotor:
        """The sandboxed version of a motor (or motor name) for this primitive."""
        return self.robot.mockup(motor)

    def affect_once(self, motor: Motor | MockupMotor | str, register: str, value: Any) -> None:
        """Write ``register`` of the real motor once, outside the manager (pypot's).

        A request (``self.robot.m1.led = 'red'``) is applied again at every manager tick; a value
        affected once stays only until something else writes it (the user, another primitive).

        Raises:
            UnknownMotorError: no such motor.
            RegisterError, ArgumentError: the motor refuses the value.
        """
        setattr(self.robot.mockup(motor).real_motor, register, value)

    # -- remote access -----------------------------------------------------------------------

    def get_property(self, name: str) -> Any:
        """The value of declared property ``name`` (``primitive_access.get_property``)."""
        return primitive_access.get_property(self, name)

    def set_property(self, name: str, value: Any) -> None:
        """Set declared property ``name``, text parsed (``primitive_access.set_property``)."""
        primitive_access.set_property(self, name, value)

    def property_values(self) -> dict[str, Any]:
        """Every declared property and its value."""
        return primitive_access.property_values(self)

    def call_method(self, name: str, *args: Any) -> Any:
        """Call declared method ``name`` (``primitive_access.call_method``)."""
        return primitive_access.call_method(self, name, *args)

    def describe(self) -> dict[str, Any]:
        """State, elapsed time, properties, methods and error as plain values (for JSON)."""
        return {
            "class": type(self).__name__,
            "state": self.state,
            "alive": self.is_alive(),
            "elapsed_s": round(self.elapsed_time, 3),
            "properties": self.property_values(),
            "methods": list(self.methods),
            "error": self.error.to_dict() if self.error is not None else None,
        }
