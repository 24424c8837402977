"""Typed messages that thread workers post to the TUI (post_message is thread-safe)."""
# ruff: noqa: TID253  (the TUI package is only imported by `poppy tui`, lazily)

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from textual.message import Message

if TYPE_CHECKING:
    from poppy_cli.tui.busio import LiveValues, MotorRef, RegisterRow
    from poppy_cli.tui.ops import WriteOutcome
    from poppy_core.bus import FoundMotor, PortInfo, ScanProgress
    from poppy_core.robot import Robot


@dataclass
class PortsListed(Message):
    """The serial ports now on the machine."""

    ports: list[PortInfo]


@dataclass
class ScanProgressed(Message):
    """A scan moved on."""

    progress: ScanProgress


@dataclass
class MotorFound(Message):
    """A scan found a motor."""

    motor: FoundMotor


@dataclass
class ScanFinished(Message):
    """A scan ended (``aborted`` when stopped by the user)."""

    found: int
    aborted: bool
    elapsed_s: float


@dataclass
class TableRead(Message):
    """A motor's whole control table was read."""

    motor: MotorRef
    rows: list[RegisterRow]


@dataclass
class LiveSampled(Message):
    """A live sample of one motor."""

    motor: MotorRef
    values: LiveValues


@dataclass
class ValueWritten(Message):
    """A register write to one or several motors ended (some may have refused)."""

    outcome: WriteOutcome


@dataclass
class MotorMoved(Message):
    """A motor now answers elsewhere (new ID or baud rate, after a setup operation)."""

    old: MotorRef
    new: MotorRef


@dataclass
class BusFailed(Message):
    """A bus operation failed; ``text`` is the readable reason."""

    text: str


@dataclass
class RobotOpened(Message):
    """A robot was built (its sync loops run)."""

    robot: Robot
    title: str
