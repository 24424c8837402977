"""``mimic``: a Poppy Torso's or Humanoid's arms follow a person's skeleton (Kinect or camera pose).

At each update the person's upper-arm and forearm directions, in the person's own frame
(``arm_directions.person_arms``), are turned into the robot's frame and each robot arm's four
joints (shoulder_y, shoulder_x, arm_z, elbow_y) are solved through its kinematic chain to point
the same way, within the motors' angle limits. Mirrored by default (``mirror=True``): facing the
robot, a person who raises the right arm sees the robot raise its left arm, as a mirror does;
with ``mirror=False`` each robot arm copies the person's arm of the same side. The goals are
smoothed (each new skeleton moves them ``1 - smoothing`` of the way to its solution) and
reached by a minimum-jerk goto of two update periods. Nobody tracked, or no new skeleton since
the last update: the arms keep their goals.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any, ClassVar

from poppy_core.creatures.arm_directions import (
    ArmSolver,
    Directions,
    person_arms,
    robot_arm_for,
)
from poppy_core.errors import ArgumentError, SensorError
from poppy_core.motion import LoopPrimitive
from poppy_core.motion.cartesian import RobotChain

if TYPE_CHECKING:
    from poppy_core.robot import Robot

logger = logging.getLogger(__name__)

MIMIC_HZ = 10.0
RESEED_ERROR = 0.15
"""A solution this far from the wanted directions (the residual's norm) is tried again from the
zero posture (a local minimum of the least squares)."""
ARMS = {"left": "l_arm_chain", "right": "r_arm_chain"}
"""The robot's arm -> the chain that carries it."""


def skeleton_source(robot: Robot, source: Any) -> Any:
    """The skeleton sensor ``source`` names (or is); None: the robot's first one.

    Raises:
        ArgumentError: no such sensor, or one that gives no skeletons.
    """
    if source is not None and not isinstance(source, str):
        return source
    sensors = [s for s in robot.sensors if "tracked_skeleton" in s.registers]
    if source is None:
        if not sensors:
            raise ArgumentError(
                "mimic needs a skeleton sensor (a KinectSensor or a PoseSkeleton in the config)"
            )
        return sensors[0]
    for sensor in sensors:
        if sensor.name == source:
            return sensor
    known = ", ".join(s.name for s in sensors) or "none"
    raise ArgumentError(f"no skeleton sensor {source!r} (skeleton sensors: {known})")


class Mimic(LoopPrimitive):
    """The robot's arms follow a tracked person's arms.

    Args:
        robot: a Torso or Humanoid with ``l_arm_chain`` and ``r_arm_chain``.
        source: the skeleton sensor (a ``KinectSensor``, a ``PoseSkeleton``) or its name;
            None: the robot's first.
        mirror: mirror the person (True) or copy each arm on its own side (False).
        smoothing: 0 (jump to each new goal) to 0.95 (glide): the part of the old goal kept.
        freq: updates per second.
        user: the tracked user to follow (None: the lowest user id).
    """

    properties: ClassVar[Sequence[str]] = ("mirror", "smoothing", "user", "update_freq")

    def __init__(
        self,
        robot: Robot,
        source: Any = None,
        *,
        mirror: bool = True,
        smoothing: float = 0.5,
        freq: float = MIMIC_HZ,
        user: Any = None,
    ) -> None:
        super().__init__(robot, freq)
        self.source = skeleton_source(robot, source)
        self.mirror = bool(mirror)
        self.smoothing = smoothing
        self.user = user
        self.targets: dict[str, Directions] = {}
        """Each robot arm's last wanted directions (upper arm, forearm), chain base frame."""
        self.goals: dict[str, float] = {}
        """The last joint goals sent (degrees)."""
        self.solvers: dict[str, ArmSolver] = {}
        self._warned = False
        self._followed: Any = None

    @property
    def smoothing(self) -> float:
        """The part of the previous goal kept at each update (0: none)."""
        return self._smoothing

    @smoothing.setter
    def smoothing(self, value: float) -> None:
        number = float(value)
        if not 0.0 <= number <= 0.95:
            raise ArgumentError(f"smoothing must be from 0 to 0.95, not {value!r}")
        self._smoothing = number

    def _chains(self) -> dict[str, RobotChain]:
        chains = {}
        for side, name in ARMS.items():
            chain = self.real_robot.extensions.get(name)
            if not isinstance(chain, RobotChain):
                raise RuntimeError(f"mimic needs the robot's {name} (a Poppy Torso or Humanoid)")
            chains[side] = chain
        return chains

    def _solvers(self) -> dict[str, ArmSolver]:
        solvers = {}
        for side, chain in self._chains().items():
            arm = [m.name for m in chain.active_motors]
            limits = {m.name: tuple(m.angle_limit) for m in chain.active_motors}
            solvers[side] = ArmSolver(chain.model, arm, limits)  # type: ignore[arg-type]
        return solvers

    def setup(self) -> None:
        self.solvers = self._solvers()
        for solver in self.solvers.values():
            for name in solver.arm:
                self.get_mockup_motor(name).compliant = False
        self.goals = {}
        self.targets = {}
        self._warned = False
        self._followed = None

    def skeleton(self) -> Any | None:
        """The followed person's latest skeleton (None: nobody tracked)."""
        try:
            skeletons: Mapping[Any, Any] = self.source.tracked_skeleton
        except SensorError as exc:
            if not self._warned:
                logger.warning("mimic: %s", exc)
                self._warned = True
            return None
        if not skeletons:
            health = self.source.health()
            if not health.ok and not self._warned:  # a Kinect away, no MediaPipe, a lost camera
                logger.warning("mimic: %s %s: %s", health.kind, health.name, health.last_error)
                self._warned = True
            return None
        if self.user is not None:
            return skeletons.get(self.user)
        return skeletons[min(skeletons, key=str)]

    def update(self) -> None:
        skeleton = self.skeleton()
        if skeleton is None or skeleton is self._followed:  # nobody, or nothing new
            return
        self._followed = skeleton
        arms = person_arms(skeleton)
        present = {m.name: m.present_position for m in self.real_robot.motors}
        goals: dict[str, float] = {}
        for side, solver in self.solvers.items():
            torso = {n: present[n] for n in solver.model.names if n not in solver.arm}
            frame = solver.frame(torso)  # rows forward, left, up in the base frame
            upper, fore = robot_arm_for(arms, side, self.mirror)
            want = (frame.T @ upper, frame.T @ fore)
            self.targets[side] = want
            angles, error = solver.solve(want, torso, [self.goals or present])
            if error > RESEED_ERROR:  # stuck away from it: try again from the zero posture
                again = solver.solve(want, torso, [dict.fromkeys(solver.arm, 0.0)])
                angles = min((angles, error), again, key=lambda found: found[1])[0]
            for name, angle in angles.items():
                previous = self.goals.get(name)
                keep = 0.0 if previous is None else self._smoothing
                # both within the limits, so is any mix of them
                goals[name] = keep * (previous or 0.0) + (1 - keep) * angle
        self.goals = goals
        self.robot.goto_position(goals, 2.0 * self.period_s, control="minjerk")
