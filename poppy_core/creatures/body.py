"""Torso and Humanoid upper-body motions: dance on a beat, idle motions of the body and head.

Each adds slow sinusoids to the posture the robot held when it started (looping); motors the
robot lacks are skipped, goals stay inside the angle limits (the motors clamp them).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, ClassVar

from poppy_core import checks
from poppy_core.motion import LoopPrimitive

if TYPE_CHECKING:
    from poppy_core.robot import Robot

MOTION_UPDATE_HZ = 50.0  # the primitive manager's rate (poppy_core.motion.manager)


@dataclass(frozen=True)
class Swing:
    """``amplitude_deg * sin(2π freq_hz t + phase_deg)`` added to one motor's start position."""

    motor: str
    amplitude_deg: float
    freq_hz: float
    phase_deg: float = 0.0


# Poppy documentation (upper_body_idle_motion, head_idle_motion): "Slow and small movements ...
# to have the robot look less 'dead'". poppy-humanoid's numbers are not installed here; chosen:
# a few degrees, periods of 7 to 25 s, frequencies that share no simple ratio so the motion does
# not look mechanical.
UPPER_BODY_IDLE: tuple[Swing, ...] = (
    Swing("abs_z", 5.0, 0.04),
    Swing("bust_x", 3.0, 0.07, 90.0),
    Swing("bust_y", 2.0, 0.11),
    Swing("abs_x", 1.5, 0.05, 45.0),
)
HEAD_IDLE: tuple[Swing, ...] = (
    Swing("head_z", 15.0, 0.05),
    Swing("head_z", 4.0, 0.13, 30.0),
    Swing("head_y", 4.0, 0.09, 60.0),
)
# dance_beat_motion: "shake its upper body following a given beat rate in bpm" (Poppy
# documentation). Chosen: 100 bpm, 10° swings; the head nods on every beat, the bust and the
# head sway from side to side over two beats.
DANCE_BPM = 100.0
DANCE_AMPLITUDE_DEG = 10.0


class SwingMotion(LoopPrimitive):
    """Adds sinusoids to the start positions of some motors (subclasses give ``swings()``).

    Args:
        robot: the robot.
        amplitude_scale: multiplies every amplitude.
    """

    properties: ClassVar[Sequence[str]] = ("amplitude_scale", "update_freq")

    def __init__(self, robot: Robot, amplitude_scale: float = 1.0) -> None:
        super().__init__(robot, MOTION_UPDATE_HZ)
        self.amplitude_scale = amplitude_scale
        self._centre: dict[str, float] = {}

    amplitude_scale = checks.Checked(checks.non_negative, "Multiplier of every amplitude (>= 0).")

    def swings(self) -> Sequence[Swing]:
        """The sinusoids to add."""
        return ()

    def setup(self) -> None:
        """Take each moved motor's present goal as the centre of its motion."""
        known = {m.name for m in self.real_robot.motors}
        names = {s.motor for s in self.swings() if s.motor in known}
        self._centre = {}
        for name in names:
            motor = self.real_robot.motor(name)
            self._centre[name] = motor.present_position if motor.compliant else motor.goal_position

    def offsets(self, t_s: float) -> dict[str, float]:
        """Motor name -> degrees added to its centre ``t_s`` seconds after the start."""
        out = dict.fromkeys(self._centre, 0.0)
        for swing in self.swings():
            if swing.motor in out:
                angle = 2 * math.pi * swing.freq_hz * t_s + math.radians(swing.phase_deg)
                out[swing.motor] += self.amplitude_scale * swing.amplitude_deg * math.sin(angle)
        return out

    def update(self) -> None:
        """Request centre + offset on every moved motor."""
        for name, offset in self.offsets(self.elapsed_time).items():
            self.robot.motor(name).goal_position = self._centre[name] + offset


class UpperBodyIdleMotion(SwingMotion):
    """Slow, small movements of the abdomen and bust, so the robot looks alive (looping)."""

    def swings(self) -> Sequence[Swing]:
        """The idle sinusoids of the torso."""
        return UPPER_BODY_IDLE


class HeadIdleMotion(SwingMotion):
    """Slow, small movements of the head, so the robot looks alive (looping)."""

    def swings(self) -> Sequence[Swing]:
        """The idle sinusoids of the head."""
        return HEAD_IDLE


class DanceBeatMotion(SwingMotion):
    """Shakes the upper body on a beat given in beats per minute (looping).

    Args:
        robot: the robot.
        bpm: beats per minute.
        amplitude: degrees of the largest swings.
    """

    properties: ClassVar[Sequence[str]] = ("bpm", "amplitude", "update_freq")

    def __init__(
        self, robot: Robot, bpm: float = DANCE_BPM, amplitude: float = DANCE_AMPLITUDE_DEG
    ) -> None:
        super().__init__(robot)
        self.bpm = bpm
        self.amplitude = amplitude

    bpm = checks.Checked(checks.non_negative, "Beats per minute (>= 0).")

    amplitude = checks.Checked(checks.non_negative, "Degrees of the largest swings (>= 0).")

    def swings(self) -> Sequence[Swing]:
        """Nod on each beat, sway over two beats."""
        beat_hz = self.bpm / 60.0
        amp = self.amplitude
        return (
            Swing("head_y", amp / 2, beat_hz),
            Swing("head_z", amp, beat_hz / 2),
            Swing("bust_x", amp, beat_hz / 2, 180.0),
            Swing("abs_z", amp / 2, beat_hz / 2),
        )
