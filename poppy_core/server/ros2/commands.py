"""ROS 2 commands as the service's operations: joint goals and trajectories, all or nothing.

A command names joints (the motors) with URDF angles in radians; this adapter reads the message,
turns radians into the motors' degrees and asks the service (``RobotService.set_goals``,
``follow``), whose rules are every surface's: an unknown joint or a value that is not a finite
number refuses the whole command (nothing moves); a goal beyond a motor's angle limits is
clamped to them (the limit rule, as ros2_control's saturation joint limiter does); a compliant
motor refuses it, the refusal saying to call ``set_compliant``. A trajectory runs on the motion
room's follower (``motion/waypoints.py``), at its ``header.stamp`` (a start time ahead, checked
as every ``start_at``; 0 or a past stamp: now); the next trajectory replaces it. A trajectory
leases its motors (``trajectory from ROS 2``) until it ends or is stopped; ROS 2's commands are
a strict writer: a motor another owner drives (a teleoperation, a move...) refuses them.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

from poppy_core import checks
from poppy_core.errors import ArgumentError, UnknownMotorError
from poppy_core.motion.waypoints import Waypoints
from poppy_core.server.compliant_goals import CompliantMotorError

if TYPE_CHECKING:
    from poppy_core.server.ros2.joints import UrdfJoints
    from poppy_core.server.service import RobotService

COMPLIANT_TIP = "call the node's set_compliant service with data: false first"
ROS2_WRITER = "ROS 2"
"""The node's commands and trajectories as one writer: a joint command passes its own
trajectory's lease (and replaces the trajectory), as the next trajectory does."""


class CommandRefused(ArgumentError):
    """A ROS 2 command whose shape breaks a rule (names, lengths, times); nothing moved."""


def reason(exc: BaseException) -> str:
    """The one line a ROS 2 user reads for a refusal (the service's error, in joint words)."""
    if isinstance(exc, UnknownMotorError):
        known = ", ".join(exc.known or [])
        return f"no joint {exc.motor!r} (joints: {known})"
    if isinstance(exc, CompliantMotorError):
        verb = "is" if len(exc.names) == 1 else "are"
        return f"{', '.join(exc.names)} {verb} compliant: {COMPLIANT_TIP}"
    return str(exc)


def _duration(value: Any, field: str) -> float:
    seconds = float(getattr(value, "sec", 0)) + float(getattr(value, "nanosec", 0)) * 1e-9
    return checks.in_range(seconds, 0.0, 24 * 3600.0, field, "s")


class Commands:
    """Joint commands and trajectories of a ROS 2 node, handed to ``service``."""

    def __init__(self, service: RobotService, joints: UrdfJoints) -> None:
        self.service = service
        self.joints = joints
        self.refused = 0

    def degrees(self, names: Sequence[str], radians: Sequence[Any]) -> dict[str, float]:
        """Motor -> degrees of ``names`` at ``radians`` (not yet checked against the limits).

        Raises:
            CommandRefused: no joint, a joint twice, as many positions as joints.
            UnknownMotorError: an unknown joint.
            ArgumentError: a position that is not a finite number.
        """
        if not names:
            raise CommandRefused("the command names no joint", field="name")
        if len(set(names)) != len(names):
            raise CommandRefused("the command names a joint twice", field="name")
        if len(radians) != len(names):
            raise CommandRefused(
                f"{len(names)} joints but {len(radians)} positions", field="position"
            )
        out: dict[str, float] = {}
        for name, value in zip(names, radians, strict=True):
            self.service.motor(name)  # UnknownMotorError before the joint's frame is looked up
            out[name] = self.joints.to_motor(name, checks.number(value, f"{name} position"))
        return out

    def command(self, names: Sequence[str], radians: Sequence[Any]) -> dict[str, float]:
        """Set the goals of a joint command (all or none); it replaces a running trajectory."""
        return self.service.set_goals(
            self.degrees(names, radians),
            refuse_compliant=True,
            replace_trajectory=True,
            writer=ROS2_WRITER,
        )

    def follow(self, message: Any) -> Waypoints | None:
        """Follow a trajectory_msgs/JointTrajectory (replacing the one followed); one without
        points stops it."""
        names = list(message.joint_names)
        times: list[float] = []
        points: list[list[float]] = []
        for index, point in enumerate(message.points):
            times.append(_duration(point.time_from_start, f"points[{index}].time_from_start"))
            if len(times) > 1 and times[-1] < times[-2]:
                raise CommandRefused(
                    f"points[{index}].time_from_start goes back in time", field="time_from_start"
                )
            goals = self.degrees(names, list(point.positions))
            points.append([goals[n] for n in names])
        stamp = message.header.stamp
        wall = float(stamp.sec) + float(stamp.nanosec) * 1e-9
        # 0 or a past stamp (a node on simulated time stamps seconds since its start): now
        start_at = wall if wall > time.time() else None
        return self.service.follow(
            names, times, points, start_at=start_at, writer=ROS2_WRITER, client=ROS2_WRITER
        )

    def stop(self) -> bool:
        """Stop the trajectory followed (the motors hold their goals)."""
        return self.service.stop_following()

    @property
    def following(self) -> bool:
        """True while a trajectory runs."""
        return self.service.follower.following
