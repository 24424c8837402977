"""Rotations and homogeneous transforms with numpy: URDF roll-pitch-yaw, axis-angle, quaternions."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

Matrix = NDArray[np.float64]
Vector = Sequence[float] | Matrix
"""Three numbers: a list or an array."""
"""A float array: 3-vector, 3x3 rotation or 4x4 homogeneous transform."""


def rot_x(angle_rad: float) -> Matrix:
    """Rotation of ``angle_rad`` about x."""
    c, s = math.cos(angle_rad), math.sin(angle_rad)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def rot_y(angle_rad: float) -> Matrix:
    """Rotation of ``angle_rad`` about y."""
    c, s = math.cos(angle_rad), math.sin(angle_rad)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rot_z(angle_rad: float) -> Matrix:
    """Rotation of ``angle_rad`` about z."""
    c, s = math.cos(angle_rad), math.sin(angle_rad)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def rpy_matrix(roll: float, pitch: float, yaw: float) -> Matrix:
    """URDF roll-pitch-yaw (radians; fixed axes x, then y, then z): ``Rz(yaw) Ry(pitch) Rx(roll)``.

    ikpy's ``rpy_matrix`` (behind pypot's REST ``rpy.json``) is the same product.
    """
    return rot_z(yaw) @ rot_y(pitch) @ rot_x(roll)


def matrix_rpy(rotation: Matrix) -> tuple[float, float, float]:
    """The roll, pitch, yaw (radians) of a rotation matrix, inverse of ``rpy_matrix``."""
    r = np.asarray(rotation, dtype=float)
    pitch = math.atan2(-r[2, 0], math.hypot(r[0, 0], r[1, 0]))
    if abs(math.cos(pitch)) < 1e-9:  # gimbal lock: put the whole rotation in yaw
        return 0.0, pitch, math.atan2(-r[0, 1], r[1, 1])
    return math.atan2(r[2, 1], r[2, 2]), pitch, math.atan2(r[1, 0], r[0, 0])


def axis_angle_matrix(axis: Sequence[float] | Matrix, angle_rad: float) -> Matrix:
    """Rotation of ``angle_rad`` about ``axis`` (normalised here), by Rodrigues' formula."""
    a = np.asarray(axis, dtype=float)
    a = a / np.linalg.norm(a)
    k = skew(a)
    return np.eye(3) + math.sin(angle_rad) * k + (1.0 - math.cos(angle_rad)) * (k @ k)


def quat_mul(
    a: tuple[float, float, float, float], b: tuple[float, float, float, float]
) -> tuple[float, float, float, float]:
    """Hamilton product ``a * b`` of quaternions ``(w, x, y, z)`` (plain floats, no numpy)."""
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return (
        aw * bw - ax * bx - ay * by - az * bz,
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
    )


def quat_matrix(quat: Sequence[float]) -> Matrix:
    """Rotation matrix of a quaternion ``(w, x, y, z)`` (normalised here)."""
    w, x, y, z = np.asarray(quat, dtype=float) / np.linalg.norm(quat)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def skew(v: Matrix) -> Matrix:
    """The matrix ``K`` with ``K @ u == cross(v, u)``."""
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def homogeneous(
    rotation: Matrix | None = None, translation: Sequence[float] | Matrix | None = None
) -> Matrix:
    """The 4x4 transform of a rotation (identity when None) and a translation (zero when None)."""
    out = np.eye(4)
    if rotation is not None:
        out[:3, :3] = rotation
    if translation is not None:
        out[:3, 3] = translation
    return out


def rotation_log(rotation: Matrix) -> Matrix:
    """The rotation vector (axis times angle, radians) of a rotation matrix."""
    r = np.asarray(rotation, dtype=float)
    cos = max(-1.0, min(1.0, (np.trace(r) - 1.0) / 2.0))
    angle = math.acos(cos)
    vee = np.array([r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]])
    if angle < 1e-9:
        return vee / 2.0
    if math.pi - angle < 1e-6:
        # near a half turn the antisymmetric part vanishes: take the axis from the symmetric part
        axis = np.sqrt(np.maximum((np.diag(r) + 1.0) / 2.0, 0.0))
        index = int(np.argmax(axis))
        signs = np.sign(r[index] + r[:, index])
        signs[index] = 1.0
        axis = axis * signs
        out: Matrix = axis / np.linalg.norm(axis) * angle
        return out
    return vee * (angle / (2.0 * math.sin(angle)))
