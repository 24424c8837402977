"""``Leader``: what a teleoperation needs of the robot moved by hand (a local ``Robot``, or a
robot served on Zenoh, ``remote.zenoh_teleop.ZenohLeader``)."""

from __future__ import annotations

from collections.abc import Sequence
from contextlib import AbstractContextManager
from typing import Protocol


class LeaderMotor(Protocol):
    """One joint of the leader: read where the hand put it, made compliant for the hand."""

    @property
    def name(self) -> str:
        """The motor's name."""
        ...

    @property
    def present_position(self) -> float:
        """Where it is (degrees, the leader's calibrated frame)."""
        ...

    @property
    def online(self) -> bool:
        """False while it does not answer (the follower then holds)."""
        ...

    @property
    def compliant(self) -> bool:
        """True when the hand can move it."""
        ...

    @compliant.setter
    def compliant(self, value: bool) -> None: ...


class Leader(Protocol):
    """The robot moved by hand: its motors, and its present state read at the teleoperation's
    pace (``driving("present")`` takes the loop from the sync thread, ``run_loop`` runs it)."""

    @property
    def motors(self) -> Sequence[LeaderMotor]:
        """Every motor of the leader."""
        ...

    def motor(self, name: str) -> LeaderMotor:
        """The motor called ``name`` (UnknownMotorError when there is none)."""
        ...

    def driving(self, name: str) -> AbstractContextManager[None]:
        """Within the block, the caller runs loop ``name`` (``run_loop``), not the sync thread."""
        ...

    def run_loop(self, name: str) -> None:
        """Run loop ``name`` once now (``"present"``: read the present state)."""
        ...
