"""Camera framing maths of the MuJoCo models: a robot's reach and cameras that keep it in view."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from poppy_core.sim.urdf import Vec3

# The model's cameras frame the whole robot and everything its limbs can reach (a ball around
# the root as wide as the longest chain, cut by the table or the floor), in a 4:3 image with
# their vertical field of view, leaving a margin at the edges.
FRONT_FOVY_DEG = 45.0
FRONT_ASPECT = 4 / 3
FRONT_MARGIN = 0.9  # the framed points stay within 90% of the half-width and half-height


@dataclass(frozen=True)
class View:
    """A named camera of the models: the direction from the robot to the eye."""

    name: str
    direction: Vec3


def norm(v: Vec3) -> float:
    return math.sqrt(sum(c * c for c in v))


def clean(v: Vec3) -> Vec3:
    """``v`` without rounding noise (1e-15 written as 0)."""
    x, y, z = (round(c, 6) + 0.0 for c in v)
    return (x, y, z)


def cross(a: Vec3, b: Vec3) -> Vec3:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def sub(a: Vec3, b: Vec3) -> Vec3:
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def dot(a: Vec3, b: Vec3) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def unit(v: Vec3) -> Vec3:
    n = norm(v)
    return (v[0] / n, v[1] / n, v[2] / n)


def along(offset: Vec3, axis: Vec3) -> bool:
    """Whether ``offset`` lies on the line of ``axis`` (a point a hinge does not move)."""
    length = norm(offset)
    return length < 1e-6 or norm(cross(offset, axis)) < 1e-6 * max(1.0, length) + 1e-9


def reach_points(centre: Vec3, radius: float, floor_z: float) -> list[Vec3]:
    """Points on the ball of ``radius`` around ``centre``, those below ``floor_z`` lifted to it."""
    points: list[Vec3] = []
    for i in range(13):  # latitude, pole to pole
        polar = math.pi * i / 12
        for j in range(24):
            azimuth = 2 * math.pi * j / 24
            x = centre[0] + radius * math.sin(polar) * math.cos(azimuth)
            y = centre[1] + radius * math.sin(polar) * math.sin(azimuth)
            z = max(floor_z, centre[2] + radius * math.cos(polar))
            points.append((x, y, z))
    return points


def _right_of(forward: Vec3) -> Vec3:
    """The image's right for a camera looking along ``forward`` with world +z up (+x when it
    looks straight down or up)."""
    side = cross(forward, (0.0, 0.0, 1.0))
    return unit(side) if norm(side) > 1e-9 else (1.0, 0.0, 0.0)


def frame_points(
    points: list[Vec3] | np.ndarray,
    view: Vec3,
    fovy_deg: float = FRONT_FOVY_DEG,
    aspect: float = FRONT_ASPECT,
    margin: float = FRONT_MARGIN,
) -> tuple[Vec3, Vec3]:
    """A camera position and the point it looks at, seeing every point of ``points`` from the
    direction ``view`` within ``margin`` of a ``fovy_deg`` × ``aspect`` frame."""
    cloud = np.asarray(points, dtype=float).reshape(-1, 3)
    target = (cloud.min(axis=0) + cloud.max(axis=0)) / 2
    back = np.asarray(unit(view))
    forward = -back
    right = np.asarray(_right_of((float(forward[0]), float(forward[1]), float(forward[2]))))
    up = np.cross(right, forward)
    tan_v = math.tan(math.radians(fovy_deg) / 2) * margin
    tan_h = tan_v * aspect
    # in the camera's axes, relative to the target: the eye moves back along ``back``
    rel = cloud - target
    x, y, z = rel @ right, rel @ up, rel @ forward

    def fits(distance: float) -> bool:
        depth = z + distance
        return bool(
            (depth > 0.01).all()
            and (np.abs(x) <= tan_h * depth).all()
            and (np.abs(y) <= tan_v * depth).all()
        )

    near, far = 0.01, 1.0
    while not fits(far):
        far *= 2
    for _ in range(40):
        middle = (near + far) / 2
        near, far = (near, middle) if fits(middle) else (middle, far)
    eye = target + far * back
    return (
        clean((float(eye[0]), float(eye[1]), float(eye[2]))),
        clean((float(target[0]), float(target[1]), float(target[2]))),
    )


def camera_axes(eye: Vec3, target: Vec3) -> tuple[Vec3, Vec3]:
    """MuJoCo ``xyaxes`` of a camera at ``eye`` looking at ``target`` (world +z up)."""
    forward = unit(sub(target, eye))
    right = _right_of(forward)
    return clean(right), clean(cross(right, forward))


def pose_cloud(
    xml: str,
    assets: dict[str, bytes],
    floor_z: float,
    seed: int = 0,
    poses: int = 300,
    *,
    follow_com: bool = False,
) -> np.ndarray:
    """Points (n, 3) bounding the robot over its joints' range: every robot geom's bounding
    ball at the model's pose, at the zero pose, each joint at 90% and 100% of its limits each
    way (all together) and ``poses`` random poses (seeded), lifted to ``floor_z`` where they
    dip below (the table or the floor stops the limbs). The root stays where the model puts it.
    ``follow_com``: for cameras that follow the centre of mass (``trackcom``), each pose's
    points are moved back by how far its centre of mass moved from the zero pose's."""
    import mujoco

    model = mujoco.MjModel.from_xml_string(xml, assets)
    data = mujoco.MjData(model)
    hinges = [j for j in range(model.njnt) if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE]
    ranges = np.array([model.jnt_range[j] for j in hinges])
    rng = np.random.default_rng(seed)
    angles = [np.zeros(len(hinges))]
    for share in (0.9, 1.0):
        angles += [share * ranges[:, 0], share * ranges[:, 1]]
    angles += list(rng.uniform(ranges[:, 0], ranges[:, 1], size=(poses, len(hinges))))
    geoms = [g for g in range(model.ngeom) if model.geom_bodyid[g] != 0]
    # each geom's bounding ball (``geom_rbound`` around its centre), by 14 points on it: the
    # axes' ends and the cube's corners
    signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
    directions = np.concatenate([np.eye(3), -np.eye(3), signs / math.sqrt(3)])
    radii = np.array([float(model.geom_rbound[g]) for g in geoms])
    offsets = radii[:, None, None] * directions[None, :, :]  # (geoms, 14, 3), world axes
    mujoco.mj_resetData(model, data)  # the model's own pose (qpos0): where the cameras start
    mujoco.mj_kinematics(model, data)
    mujoco.mj_comPos(model, data)
    start_com = np.array(data.subtree_com[0])
    clouds = []
    for pose in [None, *angles]:
        mujoco.mj_resetData(model, data)
        for joint, angle in zip(hinges, pose if pose is not None else [], strict=False):
            data.qpos[model.jnt_qposadr[joint]] = angle
        mujoco.mj_kinematics(model, data)
        mujoco.mj_comPos(model, data)
        points = (data.geom_xpos[geoms][:, None, :] + offsets).reshape(-1, 3)
        points[:, 2] = np.maximum(points[:, 2], floor_z)
        com = np.array(data.subtree_com[0])
        clouds.append(points - (com - start_com) if follow_com else points)
    return np.concatenate(clouds)
