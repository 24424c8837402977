"""Read the facts of a URDF (links, joints, origins, axes, inertias, meshes) with xml.etree."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

from poppy_core.errors import ConfigError
from poppy_core.kinematics.transforms import quat_mul

Vec3 = tuple[float, float, float]
Quat = tuple[float, float, float, float]  # (w, x, y, z), MuJoCo's order


@dataclass(frozen=True)
class Inertial:
    """Mass properties of a link, in the link frame."""

    mass_kg: float
    com: Vec3
    inertia: tuple[float, float, float, float, float, float]  # ixx iyy izz ixy ixz iyz


@dataclass(frozen=True)
class Visual:
    """A link's visual mesh: the file name (the last part of ``<mesh filename>``) and its origin
    in the link frame."""

    mesh: str
    xyz: Vec3
    rpy: Vec3


@dataclass(frozen=True)
class UrdfJoint:
    """A joint: its parent and child links, origin (xyz, rpy), axis and type."""

    name: str
    kind: str
    parent: str
    child: str
    xyz: Vec3
    rpy: Vec3
    axis: Vec3


@dataclass(frozen=True)
class Urdf:
    """A robot description: links (with inertials) and joints, in file order."""

    name: str
    links: dict[str, Inertial | None]
    joints: list[UrdfJoint]
    visuals: dict[str, Visual] = field(default_factory=dict)

    @property
    def root(self) -> str:
        """The link that is no joint's child."""
        children = {j.child for j in self.joints}
        roots = [name for name in self.links if name not in children]
        if len(roots) != 1:
            raise ConfigError(f"URDF {self.name}: expected one root link, found {roots}")
        return roots[0]

    def children(self, link: str) -> list[UrdfJoint]:
        """Joints whose parent is ``link``."""
        return [j for j in self.joints if j.parent == link]


def _vec(text: str | None, default: Vec3 = (0.0, 0.0, 0.0)) -> Vec3:
    if not text:
        return default
    values = [float(v) for v in text.split()]
    return (values[0], values[1], values[2])


def _inertial(link: ET.Element) -> Inertial | None:
    node = link.find("inertial")
    if node is None:
        return None
    mass = node.find("mass")
    inertia = node.find("inertia")
    origin = node.find("origin")
    if mass is None or inertia is None:
        return None
    get = inertia.attrib
    return Inertial(
        float(mass.attrib["value"]),
        _vec(origin.get("xyz") if origin is not None else None),
        tuple(float(get[k]) for k in ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")),  # type: ignore[arg-type]
    )


def _visual(link: ET.Element) -> Visual | None:
    mesh = link.find("visual/geometry/mesh")
    if mesh is None or not mesh.get("filename"):
        return None
    origin = link.find("visual/origin")
    name = str(mesh.get("filename")).replace("\\", "/").rsplit("/", 1)[-1]
    return Visual(
        name,
        _vec(origin.get("xyz") if origin is not None else None),
        _vec(origin.get("rpy") if origin is not None else None),
    )


def parse_urdf(path: Path) -> Urdf:
    """Parse the URDF at ``path``.

    Raises:
        ConfigError: the file is not a URDF with one root link.
    """
    try:
        root = ET.parse(path).getroot()
    except (OSError, ET.ParseError) as exc:
        raise ConfigError(f"cannot read URDF: {exc}", file=str(path)) from exc
    links = {link.attrib["name"]: _inertial(link) for link in root.findall("link")}
    joints = []
    for node in root.findall("joint"):
        origin = node.find("origin")
        axis = node.find("axis")
        parent, child = node.find("parent"), node.find("child")
        if parent is None or child is None:
            raise ConfigError(f"joint {node.get('name')} lacks a parent or child", file=str(path))
        joints.append(
            UrdfJoint(
                name=node.attrib["name"],
                kind=node.attrib.get("type", "fixed"),
                parent=parent.attrib["link"],
                child=child.attrib["link"],
                xyz=_vec(origin.get("xyz") if origin is not None else None),
                rpy=_vec(origin.get("rpy") if origin is not None else None),
                axis=_vec(axis.get("xyz") if axis is not None else None, (1.0, 0.0, 0.0)),
            )
        )
    visuals = {}
    for link in root.findall("link"):
        visual = _visual(link)
        if visual is not None:
            visuals[link.attrib["name"]] = visual
    return Urdf(root.attrib.get("name", path.stem), links, joints, visuals)


# ---------------------------------------------------------------------- rotations (w, x, y, z)


def quat_from_axis_angle(axis: Vec3, angle_rad: float) -> Quat:
    """Rotation of ``angle_rad`` about ``axis`` (normalised here)."""
    norm = math.sqrt(sum(c * c for c in axis)) or 1.0
    s = math.sin(angle_rad / 2) / norm
    return (math.cos(angle_rad / 2), axis[0] * s, axis[1] * s, axis[2] * s)


def quat_from_rpy(rpy: Vec3) -> Quat:
    """URDF roll-pitch-yaw (fixed axes x, then y, then z) as a quaternion."""
    roll, pitch, yaw = rpy
    qx = quat_from_axis_angle((1.0, 0.0, 0.0), roll)
    qy = quat_from_axis_angle((0.0, 1.0, 0.0), pitch)
    qz = quat_from_axis_angle((0.0, 0.0, 1.0), yaw)
    return quat_mul(qz, quat_mul(qy, qx))


def rotate(q: Quat, v: Vec3) -> Vec3:
    """``v`` rotated by ``q``."""
    _, x, y, z = quat_mul(quat_mul(q, (0.0, *v)), (q[0], -q[1], -q[2], -q[3]))
    return (x, y, z)


def conjugate(q: Quat) -> Quat:
    """The inverse rotation of a unit quaternion."""
    return (q[0], -q[1], -q[2], -q[3])
