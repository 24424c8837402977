"""A robot's home pose in its URDF: each motor's own angle there, its hinge axis, each link's frame.

The MuJoCo models (``sim/mjcf.py``) are drawn at this pose. A joint angle is the motor's own
angle (the one its control table holds), as pypot reads the Poppy URDFs: the URDF angle, turned
the other way for the motors the profile's ``kinematics.reversed`` lists (a URDF axis against
the servo's). The home pose is every motor at 0° in the user frame, so a motor's own angle
there is ``sign * offset`` (its orientation's sign).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from poppy_core.documents import CONFIG_LIMITS, parse_yaml, read_limited
from poppy_core.kinematics.transforms import quat_mul
from poppy_core.sim.urdf import (
    Quat,
    Urdf,
    UrdfJoint,
    Vec3,
    quat_from_axis_angle,
    quat_from_rpy,
    rotate,
)

# every link's world pose (position, orientation) at the home pose, the root at the origin
Frames = dict[str, tuple[Vec3, Quat]]


def load_profile_data(profiles_dir: Path, robot: str) -> dict[str, Any]:
    """``profiles/<robot>/profile.yaml``, read and parsed within a config's bounds."""
    path = profiles_dir / robot / "profile.yaml"
    text = read_limited(path, CONFIG_LIMITS.max_bytes, "profile")
    data: dict[str, Any] = parse_yaml(text, str(path), CONFIG_LIMITS)
    return data


def load_profile_motors(profiles_dir: Path, robot: str) -> dict[str, dict[str, Any]]:
    """The ``motors`` section of ``profiles/<robot>/profile.yaml``."""
    motors: dict[str, dict[str, Any]] = load_profile_data(profiles_dir, robot)["motors"]
    return motors


def reversed_joints(profiles_dir: Path, robot: str) -> frozenset[str]:
    """The motors whose URDF axis turns against the servo (``kinematics.reversed``)."""
    section = load_profile_data(profiles_dir, robot).get("kinematics") or {}
    return frozenset(section.get("reversed") or ())


@dataclass(frozen=True)
class HomePose:
    """``urdf`` at the home pose of the profile's ``motors`` (their ``orientation`` and
    ``offset``); ``reversed``: the motors whose URDF axis turns against the servo."""

    urdf: Urdf
    motors: dict[str, dict[str, Any]]
    reversed: frozenset[str] = frozenset()

    def axis(self, joint: UrdfJoint) -> Vec3:
        """The hinge axis: the URDF's, the other way round for a reversed motor."""
        k = -1.0 if joint.name in self.reversed else 1.0
        return (k * joint.axis[0], k * joint.axis[1], k * joint.axis[2])

    def home_deg(self, joint: UrdfJoint) -> float:
        """The motor's own angle at the home pose (user 0°): ``sign * offset``."""
        motor = self.motors.get(joint.name)
        if motor is None or joint.kind not in ("revolute", "continuous"):
            return 0.0
        sign = 1.0 if motor.get("orientation", "direct") == "direct" else -1.0
        return sign * float(motor.get("offset", 0.0))

    def joint_quat(self, joint: UrdfJoint) -> Quat:
        """The child body's frame at the home pose (the joint turned to its home angle)."""
        base = quat_from_rpy(joint.rpy)
        turn = quat_from_axis_angle(self.axis(joint), math.radians(self.home_deg(joint)))
        return quat_mul(base, turn)

    def world_frames(self) -> Frames:
        """World pose of every link at the home pose (root at the origin)."""
        poses: Frames = {self.urdf.root: ((0.0, 0.0, 0.0), (1, 0, 0, 0))}
        pending = [self.urdf.root]
        while pending:
            link = pending.pop()
            pos, quat = poses[link]
            for joint in self.urdf.children(link):
                offset = rotate(quat, joint.xyz)
                child_pos = (pos[0] + offset[0], pos[1] + offset[1], pos[2] + offset[2])
                poses[joint.child] = (child_pos, quat_mul(quat, self.joint_quat(joint)))
                pending.append(joint.child)
        return poses
