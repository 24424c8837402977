"""``RobotChain``: a kinematic chain bound to a robot's motors (pypot's ``IKChain`` API), its moves.

``robot.chain`` (Ergo Jr), ``robot.l_arm_chain`` / ``robot.r_arm_chain`` (Torso, Humanoid) are
RobotChains: they read the motors' present positions for ``position``/``orientation``/``pose``,
solve with the current posture as the seed, and move every active motor in one synchronised
goto (``goto``) or along a straight line of the tip (``goto_linear``).
"""

from __future__ import annotations

import logging
import math
import threading
import time
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from poppy_core import checks
from poppy_core.errors import ArgumentError, KinematicsError
from poppy_core.kinematics import (
    Chain,
    KinematicDescription,
    KinematicsSpec,
    MotorFrame,
    build_chains,
    matrix_rpy,
    rpy_matrix,
)
from poppy_core.kinematics.chain import Orientation
from poppy_core.kinematics.transforms import Matrix, Vector
from poppy_core.motion.plots import plot_chain
from poppy_core.motion.straight_line import LinearMove, plan_line

if TYPE_CHECKING:
    from poppy_core.robot import GotoHandle, Motor, Robot

logger = logging.getLogger(__name__)

LINEAR_RATE_HZ = 50.0


class RobotChain:
    """A chain of a robot's motors: forward and inverse kinematics, cartesian gotos.

    Args:
        robot: the robot whose motors the chain names.
        name: the chain's name (the attribute it is attached as).
        spec: the config's kinematics section (for this chain's definition).
        description: the kinematic model the section names.
        control: the goto control of ``goto`` (the creature's default).
    """

    def __init__(
        self,
        robot: Robot,
        name: str,
        spec: KinematicsSpec,
        description: KinematicDescription,
        control: str = "minjerk",
    ) -> None:
        self.robot = robot
        self.name = name
        self.control = control
        self._spec = KinematicsSpec(
            spec.model,
            tuple(c for c in spec.chains if c.name == name),
            spec.joint_frame,
            spec.reversed,
        )
        if not self._spec.chains:
            raise KinematicsError(f"the kinematics section has no chain {name!r}", chain=name)
        self._description = description
        self._lock = threading.Lock()
        self._signature: tuple[Any, ...] = ()
        self._chain = self._build()
        self._target: tuple[tuple[float, ...], float] | None = None

    def __repr__(self) -> str:
        return f"<RobotChain {self.name} motors={[m.name for m in self.motors]}>"

    @property
    def label(self) -> str:
        """The chain's name for people (the config's ``label``: the Ergo Jr's ``chain`` is
        ``arm``); ``name`` stays the attribute (``robot.chain``) and the APIs' name."""
        return self._spec.chains[0].shown

    # -- the model, rebuilt when a motor's orientation, offset or limits change ------------------

    def _frame(self, name: str) -> MotorFrame:
        motor = self.robot.motor(name)
        low, high = motor.angle_limit
        return MotorFrame(1.0 if motor.direct else -1.0, motor.offset, (low, high))

    def _expand(self, name: str) -> list[str]:
        groups = self.robot.motorgroups
        return [m.name for m in groups[name]] if name in groups else [name]

    def _build(self) -> Chain:
        frames = {m.name: self._frame(m.name) for m in self.robot.motors}
        chain = build_chains(self._spec, self._description, frames, self._expand)[self.name]
        self._signature = tuple(frames[n] for n in chain.names)
        return chain

    @property
    def model(self) -> Chain:
        """The pure kinematic chain, up to date with the motors' frames and limits."""
        with self._lock:
            if tuple(self._frame(n) for n in self._chain.names) != self._signature:
                self._chain = self._build()
            return self._chain

    # -- pypot's IKChain -------------------------------------------------------------------------

    @property
    def motors(self) -> list[Motor]:
        """The chain's motors, base to tip (passive ones included)."""
        return [self.robot.motor(n) for n in self._chain.names]

    @property
    def base(self) -> str:
        """The link (or body) of the model whose frame positions are expressed in."""
        return self._chain.base

    @property
    def links(self) -> frozenset[str]:
        """Names of every link (or body) of the robot's model."""
        joints = self._description.joints
        return frozenset(j.parent for j in joints) | frozenset(j.child for j in joints)

    @property
    def active_motors(self) -> list[Motor]:
        """The motors the chain moves."""
        return [self.robot.motor(n) for n in self._chain.active_names]

    @property
    def joints_position(self) -> list[float]:
        """Present positions of the chain's motors (degrees), base to tip."""
        return [m.present_position for m in self.motors]

    def _present(self) -> dict[str, float]:
        return {m.name: m.present_position for m in self.motors}

    @property
    def pose(self) -> Matrix:
        """The tip's 4x4 pose (metres) in the chain's base frame, at the present positions."""
        return self.model.forward(self._present())

    @property
    def position(self) -> Matrix:
        """The tip's ``[x, y, z]`` (metres) at the present positions."""
        return self.pose[:3, 3]

    @property
    def orientation(self) -> Matrix:
        """The tip's x axis ``[Rx.x, Rx.y, Rx.z]`` (pypot's orientation vector)."""
        return self.pose[:3, 0]

    @property
    def rpy(self) -> tuple[float, float, float]:
        """The tip's roll, pitch, yaw (radians, URDF convention)."""
        return matrix_rpy(self.pose[:3, :3])

    @staticmethod
    def rpy_to_rotation_matrix(roll: float, pitch: float, yaw: float) -> Matrix:
        """The 3x3 rotation of roll, pitch, yaw (radians), as pypot's REST ``rpy.json``."""
        return rpy_matrix(roll, pitch, yaw)

    def convert_to_ik_angles(self, joints: Sequence[float]) -> list[float]:
        """pypot's IK representation: 0, each joint's model angle (radians), 0 (pypot's ends)."""
        count = len(self.model.names)
        if len(joints) != count:
            raise KinematicsError(
                f"chain {self.name!r} has {count} joints, got {len(joints)} angles", chain=self.name
            )
        theta = self.model.to_model(np.asarray(joints, dtype=float))
        return [0.0, *(float(v) for v in theta), 0.0]

    def convert_from_ik_angles(self, joints: Sequence[float]) -> list[float]:
        """Degrees (user frame) from pypot's IK representation (``convert_to_ik_angles``)."""
        count = len(self.model.names)
        if len(joints) != count + 2:
            raise KinematicsError(
                f"chain {self.name!r}: pypot's IK angles are {count + 2} values, got {len(joints)}",
                chain=self.name,
            )
        return [float(v) for v in self.model.from_model(np.asarray(joints[1:-1], dtype=float))]

    def plot(
        self,
        joints: Sequence[float] | None = None,
        ax: Any = None,
        target: Any = None,
        show: bool = False,
    ) -> Any:
        """Draw the chain in 3D on a matplotlib axis (pypot's ``chain.plot(joints, ax)``).

        Args:
            joints: degrees, one per joint, or pypot's IK angles (``convert_to_ik_angles``);
                None: the present positions.
            ax: a 3D axis (``projection='3d'``), or None for a new one (Agg).
            target: an ``[x, y, z]`` to mark.
            show: accepted for pypot's calls; the drawing is shown by the caller's matplotlib.

        Returns:
            The axis drawn on.
        """
        values = self.joints_position if joints is None else list(joints)
        if len(values) == len(self.model.names) + 2:
            values = self.convert_from_ik_angles(values)
        return plot_chain(self.model, values, ax, target)

    def forward(self, joints: Mapping[str, float] | Sequence[float] | None = None) -> Matrix:
        """The tip pose (4x4) for ``joints`` (degrees; the motors not given where they are)."""
        return self.model.forward(joints, default=self._present())

    def solve(
        self,
        position: Vector,
        orientation: Orientation = None,
        seed: Mapping[str, float] | Sequence[float] | None = None,
    ) -> dict[str, float]:
        """The active motors' angles (degrees) that bring the tip to ``position``.

        Args:
            position: ``[x, y, z]`` in metres, in the chain's base frame.
            orientation: None, the tip's x axis ``[x, y, z]``, or a 3x3 rotation matrix.
            seed: angles to start from; the present positions when None (passive motors stay
                where they are).

        Raises:
            KinematicsError: out of reach within the angle limits (names the nearest point).
        """
        if seed is not None and not isinstance(seed, Mapping):
            return self.model.solve(position, orientation, seed)  # one angle per motor, checked
        return self.model.solve(position, orientation, {**self._present(), **(seed or {})})

    def goto(
        self,
        position: Vector,
        orientation: Orientation = None,
        duration: float = 1.0,
        wait: bool = False,
        accurate: bool = False,
        control: str | None = None,
    ) -> GotoHandle:
        """Move the tip to ``position``: every active motor in one synchronised goto.

        pypot's signature (``accurate`` is accepted and ignored: every solve is accurate).

        Raises:
            KinematicsError: out of reach (nothing moves).
        """
        del accurate
        angles = self.solve(position, orientation)
        self._aim(position, duration)
        return self.robot.goto_position(angles, duration, control or self.control, wait)

    def _aim(self, position: Vector, duration: float) -> None:
        self._target = (tuple(float(v) for v in position), time.monotonic() + duration)

    @property
    def target(self) -> list[float] | None:
        """Where the last cartesian goto sends the tip, while it runs (None after it)."""
        aimed = self._target
        if aimed is None or time.monotonic() > aimed[1]:
            return None
        return list(aimed[0])

    def goto_linear(
        self,
        position: Vector,
        orientation: Orientation = None,
        duration: float = 1.0,
        wait: bool = False,
        rate_hz: float = LINEAR_RATE_HZ,
    ) -> LinearMove:
        """Move the tip along the straight line to ``position`` (minimum-jerk timing).

        Every waypoint is solved before anything moves, each seeded with the previous one.

        Raises:
            KinematicsError: a point of the line is out of reach, or following the line needs
                a jump of the joints (nothing moves).
        """
        try:  # with both in range, a waypoint's period is within checks.period too
            checks.duration(duration, allow_zero=False)
            checks.rate(rate_hz, "rate_hz")
        except ArgumentError as exc:
            raise KinematicsError(
                f"a straight move needs a positive duration and rate: {exc}", chain=self.name
            ) from None
        count = max(2, math.ceil(duration * rate_hz))
        waypoints = plan_line(
            self.model, self.pose, self._present, self.name, position, orientation, count
        )
        move = LinearMove(self.robot, waypoints, duration / len(waypoints), self.name)
        self._aim(position, duration)
        if wait:
            move.wait()
        return move
