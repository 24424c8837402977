"""The numeric core of a serial chain: stacked transforms, forward kinematics and the Jacobian.

A chain of ``n`` revolute joints is ``F_1 R_1(q_1) F_2 R_2(q_2) ... F_n R_n(q_n) F_tip``: ``F_i``
the fixed transform leading to joint ``i`` (everything since the previous joint's rotation),
``R_i`` the rotation about its unit axis ``a_i``. The rotations are built for all joints at once
(Rodrigues), so one evaluation is ``n`` small matrix products plus a few vectorised calls.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from poppy_core.kinematics.transforms import Matrix, axis_angle_matrix, homogeneous, skew

_LEVI_CIVITA = np.zeros((3, 3, 3))
_LEVI_CIVITA[0, 1, 2] = _LEVI_CIVITA[1, 2, 0] = _LEVI_CIVITA[2, 0, 1] = 1.0
_LEVI_CIVITA[0, 2, 1] = _LEVI_CIVITA[2, 1, 0] = _LEVI_CIVITA[1, 0, 2] = -1.0


class Kinematics:
    """A chain's fixed transforms and axes, ready to evaluate.

    Attributes:
        fixed: ``(n, 4, 4)`` transforms ``F_i``.
        axes: ``(n, 3)`` unit axes ``a_i`` (in each joint's frame).
        tip: ``(4, 4)`` transform from the last joint's frame to the tip.
    """

    def __init__(self, fixed: Matrix, axes: Matrix, tip: Matrix) -> None:
        self.fixed = np.asarray(fixed, dtype=float).reshape(-1, 4, 4)
        self.axes = np.asarray(axes, dtype=float).reshape(-1, 3)
        self.tip = np.asarray(tip, dtype=float)
        # F_i R(q) = B0 + sin(q) B1 + (1 - cos(q)) B2 (Rodrigues): one einsum builds them all
        self._axes_column = self.axes[:, :, None]
        k = np.array([skew(a) for a in self.axes]).reshape(-1, 3, 3)
        basis = np.zeros((self.size, 3, 4, 4))
        basis[:, 0] = self.fixed
        basis[:, 1, :3, :3] = self.fixed[:, :3, :3] @ k
        basis[:, 2, :3, :3] = self.fixed[:, :3, :3] @ (k @ k)
        self._basis = basis.reshape(self.size, 3, 16)

    @property
    def size(self) -> int:
        """Number of joints."""
        return int(self.axes.shape[0])

    def local(self, theta: Matrix) -> Matrix:
        """``F_i R_i(theta_i)`` for every joint, ``(n, 4, 4)``."""
        coef = np.empty((self.size, 1, 3))
        coef[:, 0, 0] = 1.0
        coef[:, 0, 1] = np.sin(theta)
        coef[:, 0, 2] = 1.0 - np.cos(theta)
        return (coef @ self._basis).reshape(self.size, 4, 4)

    def frames(self, theta: Matrix) -> tuple[list[Matrix], Matrix]:
        """The frame after each joint's rotation (n 4x4 arrays) and the tip pose (4x4)."""
        local = list(self.local(theta))
        current = local[0]
        out = [current]
        for step in local[1:]:
            current = current.dot(step)
            out.append(current)
        return out, current.dot(self.tip)

    def pose(self, theta: Matrix) -> Matrix:
        """The tip pose (4x4) for the joint angles ``theta`` (radians)."""
        return self.frames(theta)[1]

    def pose_jacobian(self, theta: Matrix) -> tuple[Matrix, Matrix, Matrix]:
        """The tip pose, the position Jacobian ``(3, n)`` and the joints' world axes ``(3, n)``.

        Column ``i`` of the position Jacobian is ``z_i x (p_tip - p_i)``, with ``z_i`` the
        world axis of joint ``i`` and ``p_i`` a point on it (its frame's origin).
        """
        listed, tip = self.frames(theta)
        frames = np.array(listed)
        world_axes = (frames[:, :3, :3] @ self._axes_column)[:, :, 0].T
        arms = tip[:3, 3, None] - frames[:, :3, 3].T
        return tip, np.einsum("ijk,jn,kn->in", _LEVI_CIVITA, world_axes, arms), world_axes

    def reduced(self, active: Sequence[bool], theta: Matrix) -> Kinematics:
        """The chain of the active joints alone, the others frozen at ``theta``."""
        fixed: list[Matrix] = []
        axes: list[Matrix] = []
        pending = np.eye(4)
        for i, is_active in enumerate(active):
            pending = pending @ self.fixed[i]
            if is_active:
                fixed.append(pending)
                axes.append(self.axes[i])
                pending = np.eye(4)
            else:
                pending = pending @ homogeneous(axis_angle_matrix(self.axes[i], float(theta[i])))
        return Kinematics(np.array(fixed), np.array(axes), pending @ self.tip)

    def reach_bound_m(self) -> float:
        """An upper bound of the distance from the first joint's axis point to the tip."""
        lengths = [float(np.linalg.norm(f[:3, 3])) for f in self.fixed[1:]]
        return sum(lengths) + float(np.linalg.norm(self.tip[:3, 3]))
