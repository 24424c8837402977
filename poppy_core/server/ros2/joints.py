"""Motor angles as the URDF's joint angles (radians) and back; the URDF's tree for ``tf``.

ROS 2 tools read ``joint_states`` with the URDF of ``robot_description``: a position there is the
URDF joint's angle. The robot's kinematics section says how a motor's angle (degrees, user frame)
maps to it (``joint_frame: motor``: sign of the orientation, plus the offset), as the chains do.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from poppy_core.errors import PoppyError
from poppy_core.kinematics.transforms import axis_angle_matrix

if TYPE_CHECKING:
    from poppy_core.kinematics import JointDescription, KinematicDescription
    from poppy_core.kinematics.transforms import Matrix
    from poppy_core.robot import Robot
    from poppy_core.robot.config import RobotConfig

logger = logging.getLogger(__name__)


@dataclass(frozen=True)
class JointFrame:
    """How one motor's angle becomes its joint's: ``radians(scale * (degrees + offset))``."""

    scale: float = 1.0
    offset_deg: float = 0.0

    def to_joint(self, degrees: float) -> float:
        """Motor degrees (user frame) -> joint radians."""
        return math.radians(self.scale * (degrees + self.offset_deg))

    def to_motor(self, radians: float) -> float:
        """Joint radians -> motor degrees (user frame)."""
        return math.degrees(radians) * self.scale - self.offset_deg


class UrdfJoints:
    """The motors of ``robot`` as URDF joints, and the URDF itself (None without one)."""

    def __init__(self, robot: Robot) -> None:
        self._load(robot.config, [m.name for m in robot.motors])

    @classmethod
    def of_config(cls, config: RobotConfig | None, motors: Iterable[str]) -> UrdfJoints:
        """The joints of ``motors`` as ``config`` (a profile's) describes them, without a robot
        (``poppy dataset view --mcap``): a motor the config lacks keeps the plain frame
        (its degrees as radians)."""
        joints = cls.__new__(cls)
        joints._load(config, list(motors))
        return joints

    def _load(self, config: RobotConfig | None, motors: list[str]) -> None:
        self.frames: dict[str, JointFrame] = {name: JointFrame() for name in motors}
        self.description: KinematicDescription | None = None
        self.urdf: str | None = None
        if config is None:
            return
        from poppy_core.motion.chains import group_expander, kinematics_of

        profile = config.profile
        kind = (profile.kind or profile.name) if profile is not None else ""
        try:
            found = kinematics_of(config, kind or None)
        except PoppyError as exc:
            logger.warning("ROS 2: no robot model (%s): no robot_description nor tf", exc)
            return
        if found is None:
            return
        spec, description = found
        self.description = description
        if (spec.joint_frame or description.joint_frame) == "motor":
            expand = group_expander(config)
            reversed_ = {m for name in spec.reversed for m in expand(name)}
            for name, entry in config.motors.items():
                sign = 1.0 if entry.orientation == "direct" else -1.0
                self.frames[name] = JointFrame(
                    -sign if name in reversed_ else sign, float(entry.offset)
                )
        source = Path(description.source)
        if source.suffix.lower() == ".urdf":
            try:
                self.urdf = source.read_text()
            except OSError as exc:
                logger.warning("ROS 2: cannot read %s: %s", source, exc)

    def to_joint(self, name: str, degrees: float) -> float:
        """Motor ``name``'s degrees as its joint's radians."""
        return self.frames[name].to_joint(degrees)

    def to_motor(self, name: str, radians: float) -> float:
        """Joint ``name``'s radians as its motor's degrees."""
        return self.frames[name].to_motor(radians)

    def fixed(self) -> list[JointDescription]:
        """The joints that never move (``tf_static``)."""
        return [j for j in self.description.joints if not j.moves] if self.description else []

    def moving(self) -> list[JointDescription]:
        """The joints that turn (``tf``)."""
        return [j for j in self.description.joints if j.moves] if self.description else []


def joint_transform(joint: JointDescription, radians: float) -> Matrix:
    """The 4x4 transform from the joint's parent link to its child link at ``radians``."""
    turn = np.eye(4)
    if joint.moves:
        turn[:3, :3] = axis_angle_matrix(joint.axis, radians)
    out: Matrix = joint.origin @ turn @ joint.post
    return out


def matrix_quaternion(rotation: Matrix) -> tuple[float, float, float, float]:
    """(x, y, z, w) of a rotation matrix (Shepperd's method: the largest diagonal term first)."""
    r = np.asarray(rotation, dtype=float)
    trace = r[0, 0] + r[1, 1] + r[2, 2]
    if trace > 0:
        s = 2.0 * math.sqrt(trace + 1.0)
        w, x = 0.25 * s, (r[2, 1] - r[1, 2]) / s
        y, z = (r[0, 2] - r[2, 0]) / s, (r[1, 0] - r[0, 1]) / s
    elif r[0, 0] > r[1, 1] and r[0, 0] > r[2, 2]:
        s = 2.0 * math.sqrt(1.0 + r[0, 0] - r[1, 1] - r[2, 2])
        w, x = (r[2, 1] - r[1, 2]) / s, 0.25 * s
        y, z = (r[0, 1] + r[1, 0]) / s, (r[0, 2] + r[2, 0]) / s
    elif r[1, 1] > r[2, 2]:
        s = 2.0 * math.sqrt(1.0 + r[1, 1] - r[0, 0] - r[2, 2])
        w, x = (r[0, 2] - r[2, 0]) / s, (r[0, 1] + r[1, 0]) / s
        y, z = 0.25 * s, (r[1, 2] + r[2, 1]) / s
    else:
        s = 2.0 * math.sqrt(1.0 + r[2, 2] - r[0, 0] - r[1, 1])
        w, x = (r[1, 0] - r[0, 1]) / s, (r[0, 2] + r[2, 0]) / s
        y, z = (r[1, 2] + r[2, 1]) / s, 0.25 * s
    return float(x), float(y), float(z), float(w)
