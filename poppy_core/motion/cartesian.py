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
from dataclasses import replace
from typing import TYPE_CHECKING, Any

import numpy as np

from poppy_core import checks
from poppy_core.errors import ArgumentError, KinematicsError, PortError
from poppy_core.kinematics import (
    Chain,
    KinematicDescription,
    KinematicsSpec,
    MotorFrame,
    build_chains,
    make_target,
    matrix_rpy,
    rpy_matrix,
)
from poppy_core.kinematics.chain import Orientation
from poppy_core.kinematics.transforms import Matrix, Vector, axis_angle_matrix, rotation_log
from poppy_core.motion.plots import plot_chain
from poppy_core.schedule import Periodic, Worker
from poppy_core.trajectory import minimum_jerk_weight

if TYPE_CHECKING:
    from poppy_core.robot import GotoHandle, Motor, Robot

logger = logging.getLogger(__name__)

LINEAR_RATE_HZ = 50.0
MAX_LINEAR_JUMP_DEG = 15.0
"""Largest joint change between two waypoints of a straight line (a jump means a flip)."""


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
        waypoints = plan_line(self, position, orientation, max(2, math.ceil(duration * rate_hz)))
        move = LinearMove(self.robot, waypoints, duration / len(waypoints), self.name)
        self._aim(position, duration)
        if wait:
            move.wait()
        return move


def plan_line(
    chain: RobotChain, position: Vector, orientation: Orientation, count: int
) -> list[dict[str, float]]:
    """Joint angles of ``count`` points from the present tip pose to the target on a line.

    The tip follows minimum-jerk timing along the segment; the orientation (when asked) turns
    about one axis from the present one to the target.
    """
    model = chain.model
    start = chain.pose
    target = make_target(position, orientation, chain.name)
    chain.solve(position, orientation)  # an unreachable end is said first, as goto says it
    seeded_only = replace(model.options, restarts=0)
    begin = start[:3, 3]
    seed: dict[str, float] = chain._present()
    waypoints: list[dict[str, float]] = []
    turn = None
    if target.mode == "all":
        assert target.orientation is not None
        turn = rotation_log(target.orientation @ start[:3, :3].T)
    elif target.mode == "x":
        assert target.orientation is not None
        axis = np.cross(start[:3, 0], target.orientation)
        angle = math.atan2(float(np.linalg.norm(axis)), float(start[:3, 0] @ target.orientation))
        turn = axis / (np.linalg.norm(axis) or 1.0) * angle
    for k in range(1, count):
        tau = k / (count - 1)
        s = minimum_jerk_weight(tau)
        point = begin + s * (target.position - begin)
        goal: Matrix | None = None
        if turn is not None:
            angle = float(np.linalg.norm(turn))
            rotation = axis_angle_matrix(turn, s * angle) if angle > 0 else np.eye(3)
            goal = rotation @ start[:3, :3] if target.mode == "all" else rotation @ start[:3, 0]
        try:
            angles = model.solve(point, goal, seed, options=seeded_only)
        except KinematicsError as exc:
            where = ", ".join(f"{v:.3f}" for v in point)
            try:
                model.solve(point, goal, seed)
            except KinematicsError:
                raise KinematicsError(
                    f"the straight line leaves the reach of chain {chain.name!r} at ({where}) m: "
                    f"the nearest point there is {exc.distance_m or 0.0:.3f} m off; "
                    "use goto, or a waypoint in between",
                    chain=chain.name,
                    target=exc.target,
                    nearest=exc.nearest,
                    distance_m=exc.distance_m,
                ) from None
            raise KinematicsError(
                f"chain {chain.name!r} cannot follow the straight line near ({where}) m without "
                "turning its joints around; use goto, or a waypoint in between",
                chain=chain.name,
            ) from None
        jump = max(abs(angles[n] - seed[n]) for n in angles)
        if jump > MAX_LINEAR_JUMP_DEG:
            raise KinematicsError(
                f"chain {chain.name!r} cannot follow the straight line smoothly: its joints "
                f"would jump {jump:.0f}° near ({', '.join(f'{v:.3f}' for v in point)}) m; "
                "use goto, or a waypoint in between",
                chain=chain.name,
            )
        seed = {**seed, **angles}
        waypoints.append(angles)
    return waypoints


class LinearMove:
    """Streams the waypoints of a straight move, one short goto per period, in its own thread.

    A failure ends the move: logged once, kept in ``error`` and raised by ``wait``.
    """

    def __init__(
        self, robot: Robot, waypoints: list[dict[str, float]], period_s: float, name: str
    ) -> None:
        self._robot = robot
        self._waypoints = waypoints
        self._period_s = period_s
        self.duration_s = period_s * len(waypoints)
        self._worker = Worker(f"goto_linear {name}", self._run)
        self._worker.start()

    @property
    def error(self) -> BaseException | None:
        """What ended the move early (None: it ran to its end, was cancelled, the robot closed)."""
        return self._worker.error

    @property
    def done(self) -> bool:
        """True once the move ended (or was cancelled)."""
        return not self._worker.running

    def wait(self, timeout_s: float | None = None) -> bool:
        """Block until the move ends; False when ``timeout_s`` ran out first.

        Raises:
            Exception: what ended the move early (``error``).
        """
        return self._worker.join(timeout_s)

    def cancel(self) -> None:
        """Stop streaming waypoints (motors finish their current short goto)."""
        self._worker.request_stop()

    def _run(self, cancel: threading.Event) -> None:
        # a late waypoint goes at once and the next keep their times (no deadline is skipped)
        schedule = Periodic(self._period_s, time.monotonic(), catch_up=len(self._waypoints))
        try:
            for angles in self._waypoints:
                if cancel.is_set():
                    break
                # dummy control: each motor gets the next waypoint and the speed to reach it in
                # one period, so the servos move continuously between waypoints
                self._robot.goto_position(angles, self._period_s, control="dummy")
                schedule.advance(time.monotonic())
                delay = schedule.next_deadline - time.monotonic()
                if delay > 0 and cancel.wait(delay):
                    break
        except PortError:
            pass  # the robot closed under the move
