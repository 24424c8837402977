"""``Chain``: a serial chain of named joints from a kinematic description, in degrees and metres.

A chain is the part of a robot's tree from the parent of its first joint (the chain's base
frame) to a tip fixed to its last joint. Its joints carry the motors' names; angles come in and
go out in the motors' user frame (degrees), converted for the model as
``model_rad = radians(scale * (degrees + offset_deg))``: with a URDF that is pypot's
``sign * (angle + offset)`` (``scale`` = the orientation's sign, times -1 for a reversed motor),
with an MJCF the user angle itself.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from poppy_core.errors import ConfigError, KinematicsError
from poppy_core.kinematics.description import KinematicDescription
from poppy_core.kinematics.kernel import Kinematics
from poppy_core.kinematics.solver import Solution, SolverOptions, Target, accepted, solve
from poppy_core.kinematics.transforms import Matrix, Vector, homogeneous

JointValues = Mapping[str, float] | Sequence[float]
"""Joint angles in degrees: name -> angle (any subset), or one angle per joint in order."""
Orientation = Sequence[float] | Sequence[Sequence[float]] | Matrix | None
"""None, the tip's x axis ``[x, y, z]`` (pypot's vector orientation) or a 3x3 rotation."""


@dataclass(frozen=True)
class ChainJoint:
    """A joint of a chain and how its motor's angle maps onto the model.

    Attributes:
        name: the joint's (and its motor's) name.
        limits_deg: the motor's angle limits (user frame, degrees).
        scale: +1 or -1: the model turns ``scale`` degrees per degree of the motor.
        offset_deg: degrees added to the motor's angle before scaling.
        active: False for a passive joint, which the solver leaves where it is.
    """

    name: str
    limits_deg: tuple[float, float] = (-180.0, 180.0)
    scale: float = 1.0
    offset_deg: float = 0.0
    active: bool = True


class Chain:
    """Forward and inverse kinematics of named joints, in degrees and metres.

    Args:
        name: the chain's name (``chain``, ``l_arm_chain``...).
        description: the robot's kinematic tree.
        joints: the chain's joints, base to tip.
        tip: the tip's position in the last joint's child frame (m).
        options: the solver's tolerances and effort.

    Raises:
        ConfigError: joints not on one branch of the tree, or a bad limit or tip.
    """

    def __init__(
        self,
        name: str,
        description: KinematicDescription,
        joints: Sequence[ChainJoint],
        tip: Sequence[float] = (0.0, 0.0, 0.0),
        options: SolverOptions | None = None,
        label: str = "",
    ) -> None:
        self.name = name
        self.label = label or name
        """The chain's name in messages (the Ergo Jr's ``chain`` is its ``arm``)."""
        self.joints = tuple(joints)
        self.options = options or SolverOptions()
        names = [j.name for j in self.joints]
        if len(set(names)) != len(names):
            raise ConfigError(f"chain {name!r} names a joint twice", field=f"chains.{name}")
        path = description.path(names)
        self.base = path[0].parent
        """The link (or body) whose frame positions are expressed in."""
        self.tip = _vector(tip, f"chains.{name}.tip")
        fixed, axes = [], []
        pending = np.eye(4)
        for element in path:
            pending = pending @ element.origin
            if element.name in names:
                fixed.append(pending)
                axes.append(element.axis)
                pending = element.post
            else:
                pending = pending @ element.post
        self.kinematics = Kinematics(
            np.array(fixed), np.array(axes), pending @ homogeneous(None, self.tip)
        )
        for joint in self.joints:
            low, high = joint.limits_deg
            if not low <= high or joint.scale not in (1.0, -1.0):
                raise ConfigError(
                    f"chain {name!r}: joint {joint.name} has limits {low}..{high} "
                    f"and scale {joint.scale}",
                    field=f"chains.{name}",
                )
        self._active = np.array([j.active for j in self.joints])
        if not self._active.any():
            raise ConfigError(f"chain {name!r} has no active joint", field=f"chains.{name}")
        self._scale = np.array([j.scale for j in self.joints])
        self._offset = np.array([j.offset_deg for j in self.joints])
        bounds = np.radians(
            self._scale[:, None]
            * (np.array([j.limits_deg for j in self.joints]) + self._offset[:, None])
        )
        self._lower, self._upper = bounds.min(axis=1), bounds.max(axis=1)
        self._reduced: dict[tuple[float, ...], Kinematics] = {}

    def __repr__(self) -> str:
        return f"<Chain {self.name} joints={list(self.names)} tip={self.tip.tolist()}>"

    @property
    def names(self) -> tuple[str, ...]:
        """The joints' names, base to tip."""
        return tuple(j.name for j in self.joints)

    @property
    def active_names(self) -> tuple[str, ...]:
        """The joints the solver moves."""
        return tuple(j.name for j in self.joints if j.active)

    @property
    def rest_deg(self) -> dict[str, float]:
        """Each joint at 0°, or at its nearest limit when 0° is outside them."""
        return {j.name: min(max(0.0, j.limits_deg[0]), j.limits_deg[1]) for j in self.joints}

    # -- conversions ---------------------------------------------------------------------------

    def _degrees(self, values: JointValues | None, default: Mapping[str, float] | None) -> Matrix:
        base = dict(self.rest_deg if default is None else default)
        if values is None:
            pass
        elif isinstance(values, Mapping):
            unknown = [n for n in values if n not in base]
            if unknown:
                raise KinematicsError(
                    f"chain {self.name!r} has no joint {unknown[0]!r} "
                    f"(joints: {', '.join(self.names)})",
                    chain=self.name,
                )
            base.update({n: float(v) for n, v in values.items()})
        else:
            listed = [float(v) for v in values]
            if len(listed) != len(self.joints):
                raise KinematicsError(
                    f"chain {self.name!r} has {len(self.joints)} joints, got {len(listed)} angles",
                    chain=self.name,
                )
            base = dict(zip(self.names, listed, strict=True))
        return np.array([base[n] for n in self.names], dtype=float)

    def to_model(self, degrees: Matrix) -> Matrix:
        """Motor angles (degrees, user frame, one per joint) as model angles (radians)."""
        out: Matrix = np.radians(self._scale * (np.asarray(degrees, dtype=float) + self._offset))
        return out

    def from_model(self, theta: Matrix) -> Matrix:
        """Model angles (radians) as motor angles (degrees, user frame)."""
        out: Matrix = np.degrees(np.asarray(theta, dtype=float)) * self._scale - self._offset
        return out

    # -- forward kinematics --------------------------------------------------------------------

    def forward(
        self, joints: JointValues | None = None, default: Mapping[str, float] | None = None
    ) -> Matrix:
        """The tip pose (4x4, metres) in the base frame.

        Args:
            joints: angles in degrees: name -> angle for any subset, or one per joint.
            default: angles of the joints not given (``rest_deg`` when None).
        """
        return self.kinematics.pose(self.to_model(self._degrees(joints, default)))

    def frames(
        self, joints: JointValues | None = None, default: Mapping[str, float] | None = None
    ) -> dict[str, Matrix]:
        """Each joint's frame (after its rotation) and the tip's, name -> 4x4 (for drawing)."""
        frames, tip = self.kinematics.frames(self.to_model(self._degrees(joints, default)))
        out = {name: frames[i] for i, name in enumerate(self.names)}
        out["tip"] = tip
        return out

    def workspace_radius_m(self) -> float:
        """An upper bound of the distance from the first joint's axis point to the tip."""
        return self.kinematics.reach_bound_m()

    # -- inverse kinematics --------------------------------------------------------------------

    def solve(
        self,
        position: Vector,
        orientation: Orientation = None,
        seed: JointValues | None = None,
        *,
        options: SolverOptions | None = None,
    ) -> dict[str, float]:
        """Motor angles (degrees) of the active joints that bring the tip to ``position``.

        Passive joints stay at their ``seed`` angles. The answer respects every joint's limits.

        Args:
            position: ``[x, y, z]`` in metres, in the base frame.
            orientation: None (position only), the tip's x axis ``[x, y, z]`` (pypot's vector
                orientation) or a 3x3 rotation matrix.
            seed: angles to start from (degrees; missing joints at ``rest_deg``).
            options: tolerances and effort (the chain's when None).

        Returns:
            Active joint name -> degrees.

        Raises:
            KinematicsError: the target is out of reach within the limits (the message names
                the nearest point reached), or a malformed target.
        """
        found = self.solve_detailed(position, orientation, seed, options=options)
        return self._angles(found, seed)

    def closest(
        self,
        position: Vector,
        orientation: Orientation = None,
        seed: JointValues | None = None,
        *,
        options: SolverOptions | None = None,
    ) -> tuple[dict[str, float], Solution]:
        """Like ``solve`` for any target: the angles of the nearest pose found, and its errors.

        Raises:
            KinematicsError: a malformed target only.
        """
        found = self._search(position, orientation, seed, options)[1]
        return self._angles(found, seed), found

    def solve_detailed(
        self,
        position: Vector,
        orientation: Orientation = None,
        seed: JointValues | None = None,
        *,
        options: SolverOptions | None = None,
    ) -> Solution:
        """Like ``solve``, but the solver's ``Solution`` (active joints' model angles, errors).

        Raises:
            KinematicsError: see ``solve``.
        """
        target, found = self._search(position, orientation, seed, options)
        if not accepted(found, options or self.options):
            raise self._out_of_reach(target, found)
        return found

    def _search(
        self,
        position: Vector,
        orientation: Orientation,
        seed: JointValues | None,
        options: SolverOptions | None,
    ) -> tuple[Target, Solution]:
        target = make_target(position, orientation, self.name)
        start = self.to_model(self._degrees(seed, None))
        kinematics = self._reduced_for(start)
        active = self._active
        lower, upper = self._lower[active], self._upper[active]
        found = solve(kinematics, target, lower, upper, start[active], options or self.options)
        return target, found

    def _angles(self, solution: Solution, seed: JointValues | None) -> dict[str, float]:
        degrees = self.from_model(self._full_theta(solution.theta, seed))
        return {
            j.name: min(max(float(d), j.limits_deg[0]), j.limits_deg[1])  # rounding at a limit
            for j, d in zip(self.joints, degrees, strict=True)
            if j.active
        }

    def _reduced_for(self, theta: Matrix) -> Kinematics:
        if self._active.all():
            return self.kinematics
        key = tuple(np.round(theta[~self._active], 9))
        reduced = self._reduced.get(key)
        if reduced is None:
            if len(self._reduced) > 64:
                self._reduced.clear()
            reduced = self.kinematics.reduced(list(self._active), theta)
            self._reduced[key] = reduced
        return reduced

    def _full_theta(self, active_theta: Matrix, seed: JointValues | None) -> Matrix:
        theta = self.to_model(self._degrees(seed, None))
        theta[self._active] = active_theta
        return theta

    def _out_of_reach(self, target: Target, found: Solution) -> KinematicsError:
        goal = _triple(target.position)
        near = _triple(found.pose[:3, 3])
        what = "position" if target.orientation is None else "pose"
        message = (
            f"chain {self.label!r} cannot reach the {what} ({_xyz(goal)}) m within its joint "
            f"limits: the nearest point it reaches is ({_xyz(near)}) m, "
            f"{found.position_error_m:.3f} m away"
        )
        if target.orientation is not None:
            message += f", its orientation {found.orientation_error_deg:.1f}° off"
        return KinematicsError(
            message, chain=self.name, target=goal, nearest=near, distance_m=found.position_error_m
        )


def _triple(values: Matrix) -> tuple[float, float, float]:
    return float(values[0]), float(values[1]), float(values[2])


def _xyz(values: Sequence[float]) -> str:
    return ", ".join(f"{v:.3f}" for v in values)


def _vector(values: Sequence[float] | Matrix, field: str) -> Matrix:
    try:
        out = np.asarray(values, dtype=float).reshape(3)
    except (TypeError, ValueError):
        raise ConfigError(f"{field} must be 3 numbers [x, y, z] in metres", field=field) from None
    if not np.all(np.isfinite(out)):
        raise ConfigError(f"{field} must be finite numbers", field=field)
    return out


def make_target(
    position: Vector,
    orientation: Orientation,
    chain: str = "",
) -> Target:
    """A solver ``Target`` from user input, checked.

    Raises:
        KinematicsError: position not 3 finite numbers, orientation neither a 3-vector nor a
            rotation matrix.
    """
    try:
        point = np.asarray(position, dtype=float)
    except (TypeError, ValueError):
        point = np.zeros(0)
    if point.shape != (3,) or not np.all(np.isfinite(point)):
        raise KinematicsError(
            f"a target position is 3 finite numbers [x, y, z] in metres, not {position!r}",
            chain=chain,
        )
    if orientation is None:
        return Target(point)
    if isinstance(orientation, int | float):
        raise KinematicsError(
            f"an orientation is the tip's x axis [x, y, z] or a 3x3 rotation matrix, not the "
            f"number {orientation}: give the duration by name (goto(position, duration=...))",
            chain=chain,
        )
    try:
        rotation = np.asarray(orientation, dtype=float)
    except (TypeError, ValueError):
        rotation = np.zeros(0)
    if rotation.shape == (3,) and np.all(np.isfinite(rotation)) and np.linalg.norm(rotation) > 1e-9:
        return Target(point, rotation / np.linalg.norm(rotation))
    if rotation.shape == (3, 3) and np.all(np.isfinite(rotation)):
        u, _, vt = np.linalg.svd(rotation)
        if np.allclose(rotation @ rotation.T, np.eye(3), atol=1e-3) and np.linalg.det(u @ vt) > 0:
            return Target(point, u @ vt)
    raise KinematicsError(
        "an orientation is the tip's x axis [x, y, z] or a 3x3 rotation matrix", chain=chain
    )


def rotation_degrees(orientation_deg: Sequence[float]) -> Matrix:
    """The rotation matrix of roll, pitch, yaw in degrees (URDF convention)."""
    from poppy_core.kinematics.transforms import rpy_matrix

    roll, pitch, yaw = (math.radians(float(v)) for v in orientation_deg)
    return rpy_matrix(roll, pitch, yaw)
