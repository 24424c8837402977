"""A robot's kinematic tree read from a URDF (xml.etree) or an MJCF (compiled by MuJoCo).

Both formats become the same thing: joints from a parent frame to a child frame, each with a
fixed ``origin`` transform, an axis, and a ``post`` transform applied after the rotation (MJCF
joints turn about an anchor inside their body; URDF joints have none).
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal

import numpy as np

from poppy_core.errors import ConfigError
from poppy_core.kinematics.transforms import (
    Matrix,
    axis_angle_matrix,
    homogeneous,
    quat_matrix,
    rpy_matrix,
)

JointFrame = Literal["motor", "user"]
"""What angle a description's joints take: the motor's own angle ``sign * (user + offset)``
(pypot's convention for the Poppy URDFs, and poppy's MuJoCo models), or the user angle."""

MOVING = ("revolute", "continuous", "hinge")


@dataclass(frozen=True, eq=False)
class JointDescription:
    """One joint of the tree.

    Attributes:
        name: the joint's name (a motor's name when a motor drives it).
        kind: ``revolute``/``continuous``/``hinge`` (they turn), ``fixed``, or another kind that
            chains cannot use (``prismatic``, ``slide``, ``ball``).
        parent: the parent link (URDF) or body (MJCF).
        child: the child link or body.
        origin: 4x4 transform from the parent frame to the joint frame.
        axis: unit axis of rotation in the joint frame.
        post: 4x4 transform after the rotation (MJCF anchors), identity for URDF.
        limits_deg: the file's limits (degrees in the joint's own angle), None when unlimited.
    """

    name: str
    kind: str
    parent: str
    child: str
    origin: Matrix
    axis: Matrix
    post: Matrix = field(default_factory=lambda: np.eye(4))
    limits_deg: tuple[float, float] | None = None

    @property
    def moves(self) -> bool:
        """True for a joint that turns."""
        return self.kind in MOVING


@dataclass(frozen=True)
class KinematicDescription:
    """A kinematic tree: its joints and how their angles relate to the motors.

    Attributes:
        name: the robot's name in the file.
        source: the file it was read from.
        joints: every joint, in file order.
        joint_frame: ``"motor"``: the joints take the motor's own angle (pypot's convention for
            URDFs; poppy's MuJoCo models too). A config may say ``"user"`` instead.
    """

    name: str
    source: str
    joints: tuple[JointDescription, ...]
    joint_frame: JointFrame

    def joint(self, name: str) -> JointDescription:
        """The joint called ``name``.

        Raises:
            ConfigError: no such joint.
        """
        for joint in self.joints:
            if joint.name == name:
                return joint
        movable = ", ".join(j.name for j in self.joints if j.moves)
        raise ConfigError(
            f"{self.source}: no joint {name!r} (joints: {movable})", field="kinematics", value=name
        )

    def path(self, names: Iterable[str]) -> list[JointDescription]:
        """The joints from the parent of the first named joint to the last one, in order.

        Every named joint must lie on that path, in the given order (base to tip); joints that
        are not named must be fixed.

        Raises:
            ConfigError: an unknown joint, joints out of order or on another branch, or an
                unnamed moving joint between two named ones.
        """
        wanted = list(names)
        if not wanted:
            raise ConfigError(f"{self.source}: a chain needs at least one joint", field="motors")
        by_child = {j.child: j for j in self.joints}
        last = self.joint(wanted[-1])
        base = self.joint(wanted[0]).parent
        path = [last]
        while path[-1].parent != base:
            joint = by_child.get(path[-1].parent)
            if joint is None:
                raise ConfigError(
                    f"{self.source}: {wanted[-1]!r} does not hang from {wanted[0]!r}: list the "
                    "chain's joints from base to tip on one branch",
                    field="motors",
                )
            path.append(joint)
        path.reverse()
        on_path = [j.name for j in path]
        for name in wanted:
            if name not in on_path:
                raise ConfigError(
                    f"{self.source}: {name!r} is not between {wanted[0]!r} and {wanted[-1]!r} "
                    f"(that branch: {', '.join(on_path)})",
                    field="motors",
                    value=name,
                )
        if [n for n in on_path if n in wanted] != wanted:
            raise ConfigError(
                f"{self.source}: list the chain's joints from base to tip ({', '.join(on_path)})",
                field="motors",
            )
        for joint in path:
            if joint.name not in wanted and joint.kind != "fixed":
                raise ConfigError(
                    f"{self.source}: the {joint.kind} joint {joint.name!r} lies inside the chain: "
                    "add it to the chain's motors",
                    field="motors",
                    value=joint.name,
                )
        return path


def load_description(path: str | Path) -> KinematicDescription:
    """Read a URDF (``.urdf``) or an MJCF (``.xml``, ``.mjcf``; needs mujoco).

    Raises:
        ConfigError: the file is missing, unreadable or not a kinematic description.
    """
    file = Path(path)
    if not file.is_file():
        raise ConfigError(f"no kinematic model file {file}", file=str(file), field="kinematics")
    if file.suffix.lower() == ".urdf":
        return parse_urdf(file)
    if file.suffix.lower() in (".xml", ".mjcf"):
        return parse_mjcf(file)
    raise ConfigError(
        f"{file.name}: a kinematic model is a URDF (.urdf) or an MJCF (.xml)",
        file=str(file),
        field="kinematics.model",
    )


def _floats(text: str | None, count: int, default: float = 0.0) -> list[float]:
    if not text:
        return [default] * count
    values = [float(v) for v in text.split()]
    if len(values) != count:
        raise ValueError(f"expected {count} numbers, got {text!r}")
    return values


def parse_urdf(path: Path) -> KinematicDescription:
    """The joints of a URDF file (links are not needed for kinematics).

    Raises:
        ConfigError: unreadable XML or a joint without parent or child.
    """
    try:
        root = ET.parse(path).getroot()
    except (OSError, ET.ParseError) as exc:
        raise ConfigError(f"cannot read URDF {path}: {exc}", file=str(path)) from exc
    joints = []
    for node in root.iter("joint"):
        parent, child = node.find("parent"), node.find("child")
        if parent is None or child is None or "name" not in node.attrib:
            raise ConfigError(
                f"{path}: joint {node.get('name')!r} lacks a parent or child", file=str(path)
            )
        origin, axis, limit = node.find("origin"), node.find("axis"), node.find("limit")
        try:
            xyz = _floats(origin.get("xyz") if origin is not None else None, 3)
            rpy = _floats(origin.get("rpy") if origin is not None else None, 3)
            axis_xyz = np.array(_floats(axis.get("xyz") if axis is not None else "1 0 0", 3))
            kind = node.attrib.get("type", "fixed")
            limits = None
            if kind == "revolute" and limit is not None and "lower" in limit.attrib:
                limits = (
                    math.degrees(float(limit.attrib["lower"])),
                    math.degrees(float(limit.attrib.get("upper", "0"))),
                )
        except ValueError as exc:
            raise ConfigError(
                f"{path}: joint {node.attrib['name']!r}: {exc}", file=str(path)
            ) from exc
        norm = float(np.linalg.norm(axis_xyz))
        joints.append(
            JointDescription(
                name=node.attrib["name"],
                kind=kind,
                parent=parent.attrib["link"],
                child=child.attrib["link"],
                origin=homogeneous(rpy_matrix(*rpy), xyz),
                axis=axis_xyz / norm if norm > 0 else np.array([1.0, 0.0, 0.0]),
                limits_deg=limits,
            )
        )
    return KinematicDescription(
        root.attrib.get("name", path.stem), str(path), tuple(joints), "motor"
    )


def parse_mjcf(path: Path) -> KinematicDescription:
    """The joints of an MJCF model, as MuJoCo compiles it (defaults, frames and units resolved).

    Each hinge becomes a joint from its body's parent (or the body's previous joint) to the
    body; bodies without joints hang on fixed joints named after them. Free joints are ignored
    (a chain lives in the frame of the body its first joint hangs from).

    Raises:
        ConfigError: MuJoCo cannot load the file.
    """
    from poppy_core.extras import require

    require("mujoco", extra="sim", feature="reading an MJCF model")  # URDF needs no MuJoCo
    import mujoco

    try:
        model = mujoco.MjModel.from_xml_path(str(path))
    except (ValueError, mujoco.FatalError) as exc:
        reason = " ".join(str(exc).split())  # MuJoCo's messages span lines
        raise ConfigError(f"cannot load MJCF {path}: {reason}", file=str(path)) from exc
    kinds = {
        int(mujoco.mjtJoint.mjJNT_HINGE): "hinge",
        int(mujoco.mjtJoint.mjJNT_SLIDE): "slide",
        int(mujoco.mjtJoint.mjJNT_BALL): "ball",
    }

    def body_name(index: int) -> str:
        return mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, index) or f"body{index}"

    joints: list[JointDescription] = []
    for body in range(1, model.nbody):
        parent = body_name(int(model.body_parentid[body]))
        frame = homogeneous(quat_matrix(model.body_quat[body]), model.body_pos[body])
        ids = [
            j
            for j in range(
                model.body_jntadr[body], model.body_jntadr[body] + model.body_jntnum[body]
            )
            if int(model.jnt_type[j]) != int(mujoco.mjtJoint.mjJNT_FREE)
        ]
        if not ids:
            joints.append(
                JointDescription(
                    body_name(body),
                    "fixed",
                    parent,
                    body_name(body),
                    frame,
                    np.array([1.0, 0.0, 0.0]),
                )
            )
            continue
        for position, joint in enumerate(ids):
            name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, joint) or f"joint{joint}"
            anchor: Matrix = np.asarray(model.jnt_pos[joint], dtype=float)
            child = body_name(body) if position == len(ids) - 1 else f"{body_name(body)}/{name}"
            limits = None
            if model.jnt_limited[joint]:
                low, high = model.jnt_range[joint]
                limits = (math.degrees(float(low)), math.degrees(float(high)))
            kind = kinds.get(int(model.jnt_type[joint]), "other")
            axis: Matrix = np.asarray(model.jnt_axis[joint], dtype=float)
            # A hinge turns its body by (angle - ref): the body is drawn at the ``ref`` angle.
            ref = float(model.qpos0[model.jnt_qposadr[joint]]) if kind == "hinge" else 0.0
            unref = homogeneous(axis_angle_matrix(axis, -ref), None)
            joints.append(
                JointDescription(
                    name=name,
                    kind=kind,
                    parent=parent,
                    child=child,
                    origin=(frame if position == 0 else np.eye(4))
                    .dot(homogeneous(None, anchor))
                    .dot(unref),
                    axis=axis,
                    post=homogeneous(None, -anchor),
                    limits_deg=limits,
                )
            )
            parent = child
    name = Path(path).stem
    return KinematicDescription(name, str(path), tuple(joints), "motor")
