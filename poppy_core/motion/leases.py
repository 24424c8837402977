"""Who drives each motor's goal: one lease per motor, as ros2_control claims command interfaces.

A lease is held by what streams goals for a while (a teleoperation, a trajectory, a goal stream,
a move playing, a primitive running, a v1 chain goto) on the motors it drives, labelled with its
kind and its client (``m2: teleop from 192.168.1.20``). The service asks this registry before a
goal of a strict surface (v1, its chain gotos, Zenoh, ROS 2, the WebSocket's teleoperation) is
written: a motor another owner holds refuses it (``MotorLeasedError``, 409). pypot's plain writes
(its routes, Snap!, ZMQ, ``motor.goal_position = x``) are never refused: last write wins, as in
pypot. A lease ends when its owner is released (stop, a closed connection), or lapses by itself
once its owner is done (``alive`` False: the player ended, the trajectory ran out) or silent
(``lapse_s`` after its last ``touch``). Running primitives are read from the primitive manager
(the motors each asks a goal of); their goals are combined by the manager, as pypot's are, so
they never refuse each other.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Hashable, Iterable, Sequence
from dataclasses import dataclass, field

from poppy_core.errors import MotorLeasedError
from poppy_core.motion.manager import PrimitiveManager
from poppy_core.robot import Robot
from poppy_core.robot.robot_pypot import MANAGER_KEY

LEASES_KEY = "motor_leases"
STOP_ALL = "POST /api/v1/web/stop"
"""The robot-wide stop, which releases every lease (the page's Stop, ``poppy fleet stop``)."""


@dataclass(eq=False)
class Lease:
    """One owner of motor goals.

    Args:
        kind: ``teleop``, ``trajectory``, ``goal stream``, ``move``, ``primitive``, ``chain``.
        name: the move's or the primitive's name, a chain's ``arm goto`` ("" for the others).
        client: who asked (an address, a Zenoh sender, ``ROS 2``); "" when unknown.
        holder: who may write through this lease (the same holder's goals pass); None: the
            lease itself.
        stop: how to end it, for the refusal's line.
        alive: False once the owner is done (the lease lapses); None: until released.
        lapse_s: the lease lapses this long after its last ``touch`` (None: never).
    """

    kind: str
    name: str = ""
    client: str = ""
    holder: Hashable | None = None
    stop: str = STOP_ALL
    alive: Callable[[], bool] | None = None
    lapse_s: float | None = None
    touched: float = field(default_factory=time.monotonic)

    def __post_init__(self) -> None:
        if self.holder is None:
            self.holder = self

    @property
    def label(self) -> str:
        """``teleop from 192.168.1.20``, ``move wave from 127.0.0.1``, ``primitive sinus``."""
        what = f"{self.kind} {self.name}" if self.name else self.kind
        return f"{what} from {self.client}" if self.client else what

    def touch(self) -> None:
        """Its owner is still there (a goal stream's message)."""
        self.touched = time.monotonic()

    def live(self) -> bool:
        """Not lapsed: its owner goes on and was heard from within ``lapse_s``."""
        if self.lapse_s is not None and time.monotonic() - self.touched > self.lapse_s:
            return False
        return self.alive is None or self.alive()


class MotorLeases:
    """The leases of one robot's motors (``motor_leases(robot)``); thread-safe."""

    def __init__(self, robot: Robot) -> None:
        self._robot = robot
        self._lock = threading.Lock()
        self._owners: dict[str, Lease] = {}

    def owners(self) -> dict[str, Lease]:
        """Motor name -> its owner now (lapsed leases dropped; running primitives included)."""
        driven = self._primitive_leases()
        with self._lock:
            self._prune()
            return {**driven, **self._owners}

    def labels(self) -> dict[str, str]:
        """Motor name -> its owner's label, for the motors that have one."""
        return {motor: lease.label for motor, lease in self.owners().items()}

    def check(self, motors: Iterable[str], writer: Hashable) -> None:
        """Refuse goals of ``writer`` for motors another owner holds.

        Raises:
            MotorLeasedError: one of ``motors`` is held by another owner (nothing is taken).
        """
        names = list(motors)
        if not names:
            return
        owners = self.owners()
        if owners:
            _refuse([(m, o) for m in names if (o := owners.get(m)) and o.holder != writer])

    def take(self, lease: Lease, motors: Sequence[str], *, strict: bool = True) -> list[str]:
        """Hold ``motors`` for ``lease``; the motors taken.

        Args:
            strict: refuse when another owner holds one of them (nothing is taken); else take
                only the free ones (pypot's surfaces: their plays go on, last write wins).

        Raises:
            MotorLeasedError: with ``strict``, a motor another owner holds.
        """
        driven = self._primitive_leases()
        with self._lock:
            self._prune()
            owners = {**driven, **self._owners}
            taken = [(m, o) for m in motors if (o := owners.get(m)) and o.holder != lease.holder]
            if strict:
                _refuse(taken)
            held = {m for m, _ in taken}
            got = [m for m in motors if m not in held]
            for motor in got:
                self._owners[motor] = lease
            return got

    def release(self, lease: Lease) -> None:
        """End ``lease`` (its motors are free)."""
        with self._lock:
            for motor in [m for m, held in self._owners.items() if held is lease]:
                del self._owners[motor]

    def release_holder(self, holder: Hashable) -> None:
        """End every lease of ``holder``."""
        with self._lock:
            for motor in [m for m, held in self._owners.items() if held.holder == holder]:
                del self._owners[motor]

    def release_all(self) -> list[Lease]:
        """End every lease (the robot-wide stop); the leases that were held."""
        with self._lock:
            ended = list(dict.fromkeys(self._owners.values()))
            self._owners.clear()
        return ended

    def _prune(self) -> None:
        for motor in [m for m, lease in self._owners.items() if not lease.live()]:
            del self._owners[motor]

    def _primitive_leases(self) -> dict[str, Lease]:
        manager = self._robot.extensions.get(MANAGER_KEY)
        if not isinstance(manager, PrimitiveManager):
            return {}
        out: dict[str, Lease] = {}
        for primitive in manager.primitives:
            lease = Lease(
                "primitive",
                primitive.name,
                holder=primitive,
                stop=f"POST /api/v1/primitives/{primitive.name}/stop",
            )
            for motor in primitive.robot.goal_motors():
                out.setdefault(motor, lease)
        return out


def motor_leases(robot: Robot) -> MotorLeases:
    """The robot's lease registry, made on first use (shared by every server of the robot)."""
    existing = robot.extensions.get(LEASES_KEY)
    if isinstance(existing, MotorLeases):
        return existing
    chosen = robot.extensions.setdefault(LEASES_KEY, MotorLeases(robot))
    if not isinstance(chosen, MotorLeases):
        raise TypeError(f"robot.extensions[{LEASES_KEY!r}] is not a MotorLeases")
    return chosen


def refusal_line(taken: Sequence[tuple[str, Lease]]) -> str:
    """``m2 is driven by teleop from 192.168.1.20: stop it first (POST /api/v1/web/stop)``."""
    by_owner: dict[Lease, list[str]] = {}
    for motor, lease in taken:
        by_owner.setdefault(lease, []).append(motor)
    parts = []
    for lease, motors in by_owner.items():
        verb = "is" if len(motors) == 1 else "are"
        parts.append(
            f"{', '.join(motors)} {verb} driven by {lease.label}: stop it first ({lease.stop})"
        )
    return "; ".join(parts)


def _refuse(taken: Sequence[tuple[str, Lease]]) -> None:
    if taken:
        raise MotorLeasedError(
            refusal_line(taken), motors=[m for m, _ in taken], owner=taken[0][1].label
        )
