"""Torso and Humanoid arm interactions: an arm pushed by hand turns compliant; the right arm
mirrors the left one.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Sequence
from typing import TYPE_CHECKING, ClassVar

from poppy_core import checks
from poppy_core.motion import LoopPrimitive

if TYPE_CHECKING:
    from poppy_core.robot import Robot

logger = logging.getLogger(__name__)

ARM_JOINTS: tuple[str, ...] = ("shoulder_y", "shoulder_x", "arm_z", "elbow_y")
# Mirror: the right arm's angle for the left arm's angle. The two arms' user frames are mirror
# images: a pitch (shoulder_y, elbow_y) has the same sign on both sides, a roll or a yaw
# (shoulder_x, arm_z) the opposite sign. The profiles' limits (motor frame, as pypot's) say so
# once turned into the user frame: l_elbow_y and r_elbow_y both [-148, 1] (Humanoid),
# l_shoulder_x [-20, 195] against r_shoulder_x [-195, 20]; and pypot's PuppetMaster
# (poppy-humanoid, poppy-torso primitives/interaction.py) copies the left position with the
# sign +1 for the left arm's direct motors (shoulder_y, elbow_y) and -1 for its indirect ones.
MIRROR_SIGNS: dict[str, float] = {
    "shoulder_y": 1.0,
    "shoulder_x": -1.0,
    "arm_z": -1.0,
    "elbow_y": 1.0,
}
INTERACTION_HZ = 50.0  # the primitive manager's rate (poppy_core.motion.manager)

# arms_turn_compliant (Poppy documentation: "turns the arms compliant when a force is applied").
# Chosen values (poppy-humanoid is not installed here): a load above 20 % on any arm motor, or
# an arm motor held more than 10° from its goal, frees the whole arm; once no arm motor moved
# more than 1° during 2 s, the arm holds its new position again. The emulator's ideal plant
# reports no load, so there a push is seen through the position error.
PUSH_LOAD_PCT = 20.0
PUSH_ERROR_DEG = 10.0
STILL_DEG = 1.0
RELEASE_AFTER_S = 2.0


def arm_motors(robot: Robot, side: str) -> list[str]:
    """The arm joints (``shoulder_y``...) of ``side`` (``"l"`` or ``"r"``) the robot has."""
    names = {m.name for m in robot.motors}
    return [f"{side}_{joint}" for joint in ARM_JOINTS if f"{side}_{joint}" in names]


class ArmsCopyMotion(LoopPrimitive):
    """The left arm turns compliant; the right arm copies its motion, mirrored (looping).

    Stopping it stiffens the left arm where it was left.

    Args:
        robot: a Torso or Humanoid.
        freq: updates per second.
    """

    properties: ClassVar[Sequence[str]] = ("update_freq",)

    def __init__(self, robot: Robot, freq: float = INTERACTION_HZ) -> None:
        super().__init__(robot, freq)
        self._pairs: list[tuple[str, str]] = []

    def setup(self) -> None:
        """Free the left arm, stiffen the right one."""
        right = set(arm_motors(self.real_robot, "r"))
        self._pairs = [
            (left, "r" + left[1:])
            for left in arm_motors(self.real_robot, "l")
            if "r" + left[1:] in right
        ]
        for left, right_name in self._pairs:
            self.robot.motor(left).compliant = True
            self.robot.motor(right_name).compliant = False

    def update(self) -> None:
        """Right goal = the left position, mirrored (clamped to the right arm's limits)."""
        for left, right in self._pairs:
            position = self.real_robot.motor(left).present_position
            self.robot.motor(right).goal_position = MIRROR_SIGNS[left[2:]] * position

    def teardown(self) -> None:
        """Stiffen the left arm where it is."""
        for left, _ in self._pairs:
            self.robot.motor(left).compliant = False


class ArmsTurnCompliant(LoopPrimitive):
    """An arm pushed by hand turns compliant; held still again, it stiffens (looping).

    A push is a load above ``load_threshold`` or a position more than ``error_threshold_deg``
    away from the goal on a stiff arm motor. Fast gotos (``control="dummy"``) also open a large
    gap between goal and position: run it with ``"minjerk"`` gotos (the Torso and Humanoid
    default) or raise the threshold.

    Args:
        robot: a Torso or Humanoid.
        freq: checks per second.
        load_threshold: load (%) that counts as a push.
        error_threshold_deg: position error (degrees) that counts as a push.
        release_after_s: seconds an arm must stay still before it stiffens again.
    """

    properties: ClassVar[Sequence[str]] = (
        "load_threshold",
        "error_threshold_deg",
        "release_after_s",
        "update_freq",
        "compliant_arms",
    )

    def __init__(
        self,
        robot: Robot,
        freq: float = INTERACTION_HZ,
        load_threshold: float = PUSH_LOAD_PCT,
        error_threshold_deg: float = PUSH_ERROR_DEG,
        release_after_s: float = RELEASE_AFTER_S,
    ) -> None:
        super().__init__(robot, freq)
        self.load_threshold = checks.positive(load_threshold, "load_threshold")
        self.error_threshold_deg = checks.positive(error_threshold_deg, "error_threshold_deg")
        self.release_after_s = checks.positive(release_after_s, "release_after_s")
        self.compliant_arms: list[str] = []
        self._arms: dict[str, list[str]] = {}
        self._still_since: dict[str, float] = {}
        self._last: dict[str, dict[str, float]] = {}

    def setup(self) -> None:
        """Find the arms and forget earlier pushes (the arms keep their compliance)."""
        self._arms = {
            side: names for side in ("l", "r") if (names := arm_motors(self.real_robot, side))
        }
        self.compliant_arms = []
        self._still_since = {}
        self._last = {}

    def _pushed(self, names: Sequence[str]) -> bool:
        for name in names:
            motor = self.real_robot.motor(name)
            if motor.compliant:
                continue
            if abs(motor.present_load) > self.load_threshold:
                return True
            if abs(motor.goal_position - motor.present_position) > self.error_threshold_deg:
                return True
        return False

    def _still(self, side: str, names: Sequence[str], now: float) -> bool:
        positions = {n: self.real_robot.motor(n).present_position for n in names}
        last = self._last.get(side)
        moved = last is None or any(abs(positions[n] - last[n]) > STILL_DEG for n in names)
        if moved:
            self._last[side] = positions
            self._still_since[side] = now
            return False
        return now - self._still_since.get(side, now) >= self.release_after_s

    def update(self) -> None:
        """Free a pushed arm; stiffen a freed arm that stayed still long enough."""
        now = time.monotonic()
        for side, names in self._arms.items():
            if side not in self.compliant_arms:
                if self._pushed(names):
                    logger.info("%s arm pushed: turning it compliant", side)
                    for name in names:
                        self.robot.motor(name).compliant = True
                    self.compliant_arms = [*self.compliant_arms, side]
                    self._last.pop(side, None)
            elif self._still(side, names, now):
                logger.info("%s arm still for %.1f s: stiff again", side, self.release_after_s)
                for name in names:
                    self.robot.motor(name).compliant = False
                self.compliant_arms = [a for a in self.compliant_arms if a != side]
