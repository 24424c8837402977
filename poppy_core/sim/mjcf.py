"""Write the MuJoCo models (MJCF) of Ergo Jr, Torso and Humanoid from their public URDFs.

Run ``python -m poppy_core.sim.mjcf [profiles_dir]`` to regenerate ``profiles/<robot>/model.xml``.

Each URDF joint becomes a hinge named like the profile's motor; links get capsules between the
joint origins (no meshes) and the URDF's mass and inertia. A MuJoCo joint angle is the motor's
own angle (the one its control table holds), as pypot reads the Poppy URDFs: the URDF angle,
turned the other way for the motors the profile's ``kinematics.reversed`` lists (a URDF axis
against the servo's). The bodies are drawn at the robot's home pose (every motor at 0° in the
user frame) and each joint's ``ref`` is the motor's angle there, so the model starts at home.
See docs/simulation.md for the evidence.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from poppy_core.documents import CONFIG_LIMITS, parse_yaml, read_limited
from poppy_core.files import write_file
from poppy_core.models import model_by_name
from poppy_core.sim.servos import servo_params
from poppy_core.sim.urdf import (
    Quat,
    Urdf,
    UrdfJoint,
    Vec3,
    conjugate,
    parse_urdf,
    quat_from_axis_angle,
    quat_from_rpy,
    quat_mul,
    rotate,
)

# profiles/<robot>/<file>: the public Poppy URDFs, kept with each profile (the chains use them too)
ROBOTS: dict[str, str] = {
    "ergo-jr": "poppy_ergo_jr.urdf",
    "torso": "poppy_torso.urdf",
    "humanoid": "poppy_humanoid.urdf",
}


@dataclass(frozen=True)
class Style:
    """How a robot looks and where it stands."""

    radius_m: float
    rgba: str
    mount: str  # "table", "support" or "floor"
    view: Vec3  # direction from the robot to the `front` camera (its distance is computed)


STYLES: dict[str, Style] = {
    "ergo-jr": Style(0.012, "0.95 0.95 0.95 1", "table", (1.0, -1.0, 0.75)),
    "torso": Style(0.022, "0.92 0.92 0.9 1", "support", (1.0, -1.0, 0.3)),
    "humanoid": Style(0.025, "0.92 0.92 0.9 1", "floor", (1.0, -1.0, 0.25)),
}
# The `front` camera frames the whole robot and everything its limbs can reach (a ball around
# the root as wide as the longest chain, cut by the table or the floor), in a 4:3 image with its
# vertical field of view, leaving a margin at the edges.
FRONT_FOVY_DEG = 45.0
FRONT_ASPECT = 4 / 3
FRONT_MARGIN = 0.9  # the framed points stay within 90% of the half-width and half-height
# link -> (geom type, size) drawn at the link's centre of mass, so the robot looks like itself.
BLOBS: dict[str, dict[str, tuple[str, Vec3]]] = {
    "ergo-jr": {"tip": ("sphere", (0.018, 0.0, 0.0))},
    "torso": {"head": ("sphere", (0.055, 0.0, 0.0)), "chest": ("box", (0.07, 0.05, 0.04))},
    "humanoid": {
        "head": ("sphere", (0.055, 0.0, 0.0)),
        "chest": ("box", (0.07, 0.05, 0.04)),
        "pelvis": ("box", (0.06, 0.035, 0.03)),
    },
}


@dataclass(frozen=True)
class CameraMount:
    """Where the robot's own camera sits: in ``body``, ``ahead_m`` in front of its centre of mass
    (out of the head's shape), looking along ``look`` with ``up`` up (world axes at the zero
    pose), with a vertical field of view of ``fovy_deg``."""

    body: str
    ahead_m: float
    look: Vec3
    up: Vec3
    fovy_deg: float


# The MuJoCo camera `camera` (the name of the camera sensor in pypot's configs) sits where the
# real one does. Ergo Jr: the Raspberry Pi camera in its head (the tip), looking out along the
# end effector (-z of the tip frame, as pypot's IK tip [0, 0, -0.07]); field of view 41.4°
# vertical (Raspberry Pi camera module v1, OV5647: 53.5° × 41.4°). Torso/Humanoid: the camera
# in the head's face, looking forward (-y); the Poppy BOM names a 120° camera: 105° vertical at
# 4:3 for a pinhole of 120° horizontal.
CAMERAS: dict[str, CameraMount] = {
    "ergo-jr": CameraMount("tip", 0.02, (0.0, -1.0, 0.0), (0.0, 0.0, 1.0), 41.4),
    "torso": CameraMount("head", 0.06, (0.0, -1.0, 0.0), (0.0, 0.0, 1.0), 105.0),
    "humanoid": CameraMount("head", 0.06, (0.0, -1.0, 0.0), (0.0, 0.0, 1.0), 105.0),
}
CAMERA_NAME = "camera"
TABLE_TOP_M = 0.05
SUPPORT_TOP_M = 0.75


def _f(value: float) -> str:
    text = f"{value:.6g}"
    return "0" if text in ("-0", "0") else text


def _v(values: tuple[float, ...]) -> str:
    return " ".join(_f(v) for v in values)


def _norm(v: Vec3) -> float:
    return math.sqrt(sum(c * c for c in v))


def _clean(v: Vec3) -> Vec3:
    """``v`` without rounding noise (1e-15 written as 0)."""
    x, y, z = (round(c, 6) + 0.0 for c in v)
    return (x, y, z)


def _cross(a: Vec3, b: Vec3) -> Vec3:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _sub(a: Vec3, b: Vec3) -> Vec3:
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def _dot(a: Vec3, b: Vec3) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _unit(v: Vec3) -> Vec3:
    n = _norm(v)
    return (v[0] / n, v[1] / n, v[2] / n)


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


def frame_points(
    points: list[Vec3],
    view: Vec3,
    fovy_deg: float = FRONT_FOVY_DEG,
    aspect: float = FRONT_ASPECT,
    margin: float = FRONT_MARGIN,
) -> tuple[Vec3, Vec3]:
    """A camera position and the point it looks at, seeing every point of ``points`` from the
    direction ``view`` within ``margin`` of a ``fovy_deg`` × ``aspect`` frame."""
    lows = [min(p[k] for p in points) for k in range(3)]
    highs = [max(p[k] for p in points) for k in range(3)]
    target: Vec3 = tuple((lo + hi) / 2 for lo, hi in zip(lows, highs, strict=True))  # type: ignore[assignment]
    back = _unit(view)
    forward = (-back[0], -back[1], -back[2])
    right = _unit(_cross(forward, (0.0, 0.0, 1.0)))
    up = _cross(right, forward)
    tan_v = math.tan(math.radians(fovy_deg) / 2) * margin
    tan_h = tan_v * aspect

    def fits(distance: float) -> bool:
        eye = tuple(t + distance * b for t, b in zip(target, back, strict=True))
        for point in points:
            rel = _sub(point, eye)  # type: ignore[arg-type]
            depth = _dot(rel, forward)
            if depth <= 0.01:
                return False
            if abs(_dot(rel, right)) > tan_h * depth or abs(_dot(rel, up)) > tan_v * depth:
                return False
        return True

    near, far = 0.01, 1.0
    while not fits(far):
        far *= 2
    for _ in range(40):
        middle = (near + far) / 2
        near, far = (near, middle) if fits(middle) else (middle, far)
    eye: Vec3 = tuple(t + far * b for t, b in zip(target, back, strict=True))  # type: ignore[assignment]
    return _clean(eye), _clean(target)


def camera_axes(eye: Vec3, target: Vec3) -> tuple[Vec3, Vec3]:
    """MuJoCo ``xyaxes`` of a camera at ``eye`` looking at ``target`` (world +z up)."""
    forward = _unit(_sub(target, eye))
    right = _unit(_cross(forward, (0.0, 0.0, 1.0)))
    return _clean(right), _clean(_cross(right, forward))


def _along(offset: Vec3, axis: Vec3) -> bool:
    """Whether ``offset`` lies on the line of ``axis`` (a point a hinge does not move)."""
    length = _norm(offset)
    return length < 1e-6 or _norm(_cross(offset, axis)) < 1e-6 * max(1.0, length) + 1e-9


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


class _Writer:
    def __init__(
        self,
        robot: str,
        urdf: Urdf,
        motors: dict[str, dict[str, Any]],
        reversed_: frozenset[str] = frozenset(),
    ) -> None:
        self.robot = robot
        self.urdf = urdf
        self.motors = motors
        self.reversed = reversed_
        self.style = STYLES[robot]
        self.lines: list[str] = []

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

    def world_frames(self) -> dict[str, tuple[Vec3, Quat]]:
        """World pose of every link at poppy's zero pose (root at the origin)."""
        poses: dict[str, tuple[Vec3, Quat]] = {self.urdf.root: ((0.0, 0.0, 0.0), (1, 0, 0, 0))}
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

    def reach(self) -> tuple[Vec3, float]:
        """A ball holding every part of the robot whatever its pose: its centre (root frame, at
        the zero pose) and radius.

        The centre is the last pivot of the trunk that no joint moves (each joint's next offset
        along its own axis, as the Ergo Jr's m1 then m2); the radius, the longest chain of joint
        offsets from there plus the farthest point of the last link's shapes.
        """
        poses = self.world_frames()
        centre_link = self.urdf.root
        while True:
            kids = self.urdf.children(centre_link)
            if len(kids) != 1:
                break
            joint = kids[0]
            after = self.urdf.children(joint.child)
            centre_link = joint.child
            if len(after) != 1 or not _along(after[0].xyz, self.axis(joint)):
                break
        centre = poses[centre_link][0]
        radius = 0.0
        for link in poses:
            extent = self.style.radius_m
            inertial = self.urdf.links.get(link)
            if inertial is not None:
                extent += 2 * _norm(inertial.com)  # a capsule to twice the centre of mass
                blob = BLOBS.get(self.robot, {}).get(link)
                if blob is not None:
                    extent = max(extent, _norm(inertial.com) + _norm(blob[1]))
            radius = max(radius, self._path(link, centre_link) + extent)
        return centre, radius

    def _path(self, link: str, ancestor: str) -> float:
        """Length of the joint offsets from ``ancestor`` down to ``link`` (either way up)."""
        parents = {j.child: j for j in self.urdf.joints}
        length, current = 0.0, link
        while current != ancestor and current in parents:
            length += _norm(parents[current].xyz)
            current = parents[current].parent
        if current == ancestor:
            return length
        return self._path(ancestor, link)  # ``link`` is above the centre, on the trunk

    def front_camera(self, root_pos: Vec3, floor_z: float) -> str:
        """The `front` camera: the whole robot and its reach in view (see ``frame_points``)."""
        centre, radius = self.reach()
        world = (root_pos[0] + centre[0], root_pos[1] + centre[1], root_pos[2] + centre[2])
        points = reach_points(world, radius, floor_z)
        eye, target = frame_points(points, self.style.view)
        right, up = camera_axes(eye, target)
        mode = "trackcom" if self.style.mount == "floor" else "fixed"
        return (
            f'    <camera name="front" mode="{mode}" pos="{_v(eye)}" '
            f'xyaxes="{_v(right)} {_v(up)}" fovy="{_f(FRONT_FOVY_DEG)}"/>'
        )

    def geoms(self, link: str, indent: str, world_quat: Quat) -> None:
        radius = self.style.radius_m
        rgba = self.style.rgba
        inertial = self.urdf.links.get(link)
        ends = [j.xyz for j in self.urdf.children(link) if _norm(j.xyz) > 1e-3]
        feet = link.endswith("foot")
        if feet:
            ends = []
        elif not ends and inertial is not None and _norm(inertial.com) > 1e-3:
            com = inertial.com
            ends = [(2 * com[0], 2 * com[1], 2 * com[2])]
        for index, end in enumerate(ends):
            r = radius * (0.8 if index else 1.0)
            self.lines.append(
                f'{indent}<geom name="{link}_{index}" type="capsule" size="{_f(r)}" '
                f'fromto="0 0 0 {_v(end)}" rgba="{rgba}"/>'
            )
        blob = BLOBS.get(self.robot, {}).get(link)
        if blob is not None and inertial is not None:
            kind, size = blob
            self.lines.append(
                f'{indent}<geom name="{link}_body" type="{kind}" size="{_v(size)}" '
                f'pos="{_v(inertial.com)}" rgba="{rgba}"/>'
            )
        elif not ends and not feet:
            self.lines.append(
                f'{indent}<geom name="{link}_0" type="sphere" size="{_f(radius)}" rgba="{rgba}"/>'
            )
        if feet and inertial is not None:
            # flat sole, aligned with the world at the zero pose
            inv = conjugate(world_quat)
            half = (0.04, 0.09, 0.01)
            center = (inertial.com[0], inertial.com[1], inertial.com[2])
            down = rotate(inv, (0.0, 0.0, -0.015))
            pos = (center[0] + down[0], center[1] + down[1], center[2] + down[2])
            self.lines.append(
                f'{indent}<geom name="{link}_sole" type="box" size="{_v(half)}" '
                f'pos="{_v(pos)}" quat="{_v(inv)}" rgba="0.3 0.3 0.3 1"/>'
            )
        if link == self.urdf.root and self.robot == "ergo-jr":
            self.lines.append(
                f'{indent}<geom name="{link}_box" type="box" size="0.045 0.045 0.034" '
                f'pos="0 0 -0.034" rgba="0.3 0.3 0.3 1"/>'
            )

    def camera(self, link: str, indent: str, world_quat: Quat) -> None:
        """The robot's camera in ``link`` when it is the one holding it (a MuJoCo camera looks
        along its -z with +y up: its axes are the mount's, turned into the link's frame)."""
        mount = CAMERAS.get(self.robot)
        inertial = self.urdf.links.get(link)
        if mount is None or mount.body != link or inertial is None:
            return
        inv = conjugate(world_quat)
        look = _clean(rotate(inv, mount.look))
        up = _clean(rotate(inv, mount.up))
        right = _clean(_cross(look, up))
        pos = tuple(c + mount.ahead_m * d for c, d in zip(inertial.com, look, strict=True))
        self.lines.append(
            f'{indent}<camera name="{CAMERA_NAME}" pos="{_v(pos)}" '
            f'xyaxes="{_v(right)} {_v(up)}" fovy="{_f(mount.fovy_deg)}"/>'
        )

    def inertial(self, link: str, indent: str) -> None:
        inertial = self.urdf.links.get(link)
        if inertial is None:
            return
        ixx, iyy, izz, ixy, ixz, iyz = inertial.inertia
        self.lines.append(
            f'{indent}<inertial pos="{_v(inertial.com)}" mass="{_f(inertial.mass_kg)}" '
            f'fullinertia="{_v((ixx, iyy, izz, ixy, ixz, iyz))}"/>'
        )

    def body(self, joint: UrdfJoint, depth: int, poses: dict[str, tuple[Vec3, Quat]]) -> None:
        indent = "  " * depth
        quat = self.joint_quat(joint)
        self.lines.append(
            f'{indent}<body name="{joint.child}" pos="{_v(joint.xyz)}" quat="{_v(quat)}">'
        )
        self.inertial(joint.child, indent + "  ")
        if joint.kind in ("revolute", "continuous"):
            motor = self.motors.get(joint.name, {})
            low, high = motor.get("angle_limit", (-150.0, 150.0))  # motor frame, as pypot's
            servo = servo_params(model_by_name(motor.get("type", "MX-28")))
            home = self.home_deg(joint)
            ref = f' ref="{_f(math.radians(home))}"' if home else ""
            self.lines.append(
                f'{indent}  <joint name="{joint.name}" axis="{_v(self.axis(joint))}"{ref} '
                f'range="{_f(math.radians(low))} {_f(math.radians(high))}" '
                f'armature="{_f(servo.armature_kgm2)}" frictionloss="{_f(servo.friction_nm)}"/>'
            )
        self.geoms(joint.child, indent + "  ", poses[joint.child][1])
        self.camera(joint.child, indent + "  ", poses[joint.child][1])
        for child in self.urdf.children(joint.child):
            self.body(child, depth + 1, poses)
        self.lines.append(f"{indent}</body>")

    def lowest_point(self, poses: dict[str, tuple[Vec3, Quat]]) -> float:
        """Height of the lowest sole below the root at the zero pose (Humanoid)."""
        lows = []
        for link, (pos, _) in poses.items():
            inertial = self.urdf.links.get(link)
            if link.endswith("foot") and inertial is not None:
                com = rotate(poses[link][1], inertial.com)
                lows.append(pos[2] + com[2] - 0.025)
        return min(lows) if lows else 0.0

    def write(self) -> str:
        style = self.style
        poses = self.world_frames()
        root = self.urdf.root
        out = self.lines
        out += [
            f'<mujoco model="poppy-{self.robot}">',
            f"  <!-- Generated by poppy_core/sim/mjcf.py from {ROBOTS[self.robot]}: "
            "do not edit by hand. -->",
            '  <compiler angle="radian" autolimits="true"/>',
            '  <option timestep="0.002" integrator="implicitfast"/>',
            '  <visual><global offwidth="1280" offheight="960"/></visual>',
            "  <asset>",
            '    <texture name="grid" type="2d" builtin="checker" rgb1="0.82 0.84 0.86" '
            'rgb2="0.72 0.74 0.76" width="256" height="256"/>',
            '    <material name="grid" texture="grid" texrepeat="8 8" reflectance="0.1"/>',
            "  </asset>",
            "  <default>",
            '    <geom contype="2" conaffinity="1" condim="3" friction="0.8 0.02 0.001"/>',
            '    <default class="world">',
            '      <geom contype="1" conaffinity="3"/>',
            "    </default>",
            "  </default>",
            "  <worldbody>",
            '    <light name="sun" pos="0 0 3" dir="0 0 -1" directional="true"/>',
            '    <light name="key" pos="1 -1 2" dir="-1 1 -1.5"/>',
            '    <geom name="floor" class="world" type="plane" size="3 3 0.05" material="grid"/>',
        ]
        if style.mount == "table":
            top = TABLE_TOP_M
            out.append(
                f'    <geom name="table" class="world" type="box" size="0.3 0.3 {_f(top / 2)}" '
                f'pos="0 0 {_f(top / 2)}" rgba="0.55 0.4 0.3 1"/>'
            )
            root_pos: Vec3 = (0.0, 0.0, top + 0.068)
            floor_z = top
        elif style.mount == "support":
            top = SUPPORT_TOP_M
            out.append(
                f'    <geom name="support" class="world" type="box" size="0.06 0.06 {_f(top / 2)}" '
                f'pos="0 0 {_f(top / 2)}" rgba="0.3 0.3 0.3 1"/>'
            )
            root_pos = (0.0, 0.0, top)
            floor_z = 0.0
        else:
            root_pos = (0.0, 0.0, -self.lowest_point(poses) + 0.002)
            floor_z = 0.0
        out.append(self.front_camera(root_pos, floor_z))
        out.append(f'    <body name="{root}" pos="{_v(root_pos)}">')
        if style.mount == "floor":
            out.append('      <freejoint name="root"/>')
        self.inertial(root, "      ")
        self.geoms(root, "      ", poses[root][1])
        for joint in self.urdf.children(root):
            self.body(joint, 3, poses)
        out.append("    </body>")
        out.append("  </worldbody>")
        out.append("  <actuator>")
        for joint in self.urdf.joints:
            if joint.kind not in ("revolute", "continuous"):
                continue
            motor_type = self.motors.get(joint.name, {}).get("type", "MX-28")
            servo = servo_params(model_by_name(motor_type))
            out.append(
                f'    <position name="{joint.name}" joint="{joint.name}" '
                f'kp="{_f(servo.kp_nm_per_rad)}" kv="{_f(servo.kv_nms_per_rad)}" '
                f'forcerange="{_f(-servo.stall_torque_nm)} {_f(servo.stall_torque_nm)}"/>'
            )
        out.append("  </actuator>")
        out.append("</mujoco>")
        return "\n".join(out) + "\n"


def generate(robot: str, profiles_dir: Path) -> str:
    """The MJCF text of ``robot`` (``"ergo-jr"``, ``"torso"`` or ``"humanoid"``)."""
    urdf = parse_urdf(profiles_dir / robot / ROBOTS[robot])
    motors = load_profile_motors(profiles_dir, robot)
    return _Writer(robot, urdf, motors, reversed_joints(profiles_dir, robot)).write()


def write_all(profiles_dir: Path) -> list[Path]:
    """Write ``model.xml`` next to each robot's profile; returns the files written."""
    written = []
    for robot in ROBOTS:
        path = profiles_dir / robot / "model.xml"
        write_file(path, generate(robot, profiles_dir), replace=True)
        written.append(path)
    return written


def main(argv: list[str] | None = None) -> int:
    """Command-line entry: regenerate the models in ``argv[0]`` (default ``./profiles``)."""
    args = sys.argv[1:] if argv is None else argv
    write_all(Path(args[0]) if args else Path("profiles"))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
