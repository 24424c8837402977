"""Write the MuJoCo models (MJCF) of Ergo Jr, Torso and Humanoid from their public URDFs.

Run ``python -m poppy_core.sim.mjcf [profiles_dir]`` to regenerate ``profiles/<robot>/model.xml``.

Each URDF joint becomes a hinge named like the profile's motor; links get capsules between the
joint origins (no meshes) and the URDF's mass and inertia. A MuJoCo joint angle is the motor's
own angle (the one its control table holds) and the bodies are drawn at the robot's home pose
(``sim/home_pose.py``); each joint's ``ref`` is the motor's angle there, so the model starts at
home. See docs/simulation.md for the evidence.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

from poppy_core.files import write_file
from poppy_core.models import model_by_name
from poppy_core.sim.framing import (
    FRONT_FOVY_DEG,
    camera_axes,
    clean,
    cross,
    frame_points,
    norm,
    pose_cloud,
)
from poppy_core.sim.home_pose import Frames, HomePose, load_profile_motors, reversed_joints
from poppy_core.sim.looks import (
    BLOBS,
    CAMERA_NAME,
    CAMERAS,
    STYLES,
    SUPPORT_TOP_M,
    TABLE_TOP_M,
)
from poppy_core.sim.model_files import MESH_DIR
from poppy_core.sim.servos import servo_params
from poppy_core.sim.urdf import (
    Quat,
    UrdfJoint,
    Vec3,
    conjugate,
    parse_urdf,
    quat_from_rpy,
    rotate,
)

# the free camera's distance in half-spans of the robot's reach (a ball of radius r fills a 45°
# view from 2.6 r), from the front and a little above
FREE_DISTANCE = 2.8

# profiles/<robot>/<file>: the public Poppy URDFs, kept with each profile (the chains use them too)
ROBOTS: dict[str, str] = {
    "ergo-jr": "poppy_ergo_jr.urdf",
    "torso": "poppy_torso.urdf",
    "humanoid": "poppy_humanoid.urdf",
}


def _f(value: float) -> str:
    text = f"{value:.6g}"
    return "0" if text in ("-0", "0") else text


def _v(values: tuple[float, ...]) -> str:
    return " ".join(_f(v) for v in values)


class _Writer:
    def __init__(self, robot: str, home: HomePose, meshes: frozenset[str] = frozenset()) -> None:
        self.robot = robot
        self.mesh_links = meshes  # the links whose visual mesh the profile ships
        self.home = home
        self.urdf = home.urdf
        self.motors = home.motors
        self.style = STYLES[robot]
        self.lines: list[str] = []
        self.statistic = ""

    def cameras(self, cloud: np.ndarray) -> list[str]:
        """The views' cameras, each framing ``cloud`` (the robot over its joints' range, see
        ``framing.pose_cloud``), and the free camera's centre and extent (``statistic``)."""
        mode = "trackcom" if self.style.mount == "floor" else "fixed"
        lines = []
        for view in self.style.views:
            eye, target = frame_points(cloud, view.direction)
            right, up = camera_axes(eye, target)
            lines.append(
                f'    <camera name="{view.name}" mode="{mode}" pos="{_v(eye)}" '
                f'xyaxes="{_v(right)} {_v(up)}" fovy="{_f(FRONT_FOVY_DEG)}"/>'
            )
        low, high = cloud.min(axis=0), cloud.max(axis=0)
        middle = clean(
            (float(low[0] + high[0]) / 2, float(low[1] + high[1]) / 2, float(low[2] + high[2]) / 2)
        )
        # MuJoCo's free camera stands 1.5 extents away: far enough to see the half-span whole
        extent = FREE_DISTANCE * float((high - low).max()) / 2 / 1.5
        self.statistic = f'  <statistic center="{_v(middle)}" extent="{_f(extent)}"/>'
        return lines

    def geoms(self, link: str, indent: str, world_quat: Quat) -> None:
        """The link's collision shapes (capsules, blobs, soles), hidden in renders where its
        visual mesh shows it, and that mesh."""
        radius = self.style.radius_m
        visual = self.urdf.visuals.get(link)
        shown = visual is not None and link in self.mesh_links
        # the shapes' look: hidden (group 3) behind a mesh, else drawn in the robot's colour
        rgba = 'class="collision"' if shown else f'rgba="{self.style.rgba}"'
        dark = 'class="collision"' if shown else 'rgba="0.3 0.3 0.3 1"'
        inertial = self.urdf.links.get(link)
        ends = [j.xyz for j in self.urdf.children(link) if norm(j.xyz) > 1e-3]
        feet = link.endswith("foot")
        if feet:
            ends = []
        elif not ends and inertial is not None and norm(inertial.com) > 1e-3:
            com = inertial.com
            ends = [(2 * com[0], 2 * com[1], 2 * com[2])]
        for index, end in enumerate(ends):
            r = radius * (0.8 if index else 1.0)
            self.lines.append(
                f'{indent}<geom name="{link}_{index}" type="capsule" size="{_f(r)}" '
                f'fromto="0 0 0 {_v(end)}" {rgba}/>'
            )
        blob = BLOBS.get(self.robot, {}).get(link)
        if blob is not None and inertial is not None:
            kind, size = blob
            self.lines.append(
                f'{indent}<geom name="{link}_body" type="{kind}" size="{_v(size)}" '
                f'pos="{_v(inertial.com)}" {rgba}/>'
            )
        elif not ends and not feet:
            self.lines.append(
                f'{indent}<geom name="{link}_0" type="sphere" size="{_f(radius)}" {rgba}/>'
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
                f'pos="{_v(pos)}" quat="{_v(inv)}" {dark}/>'
            )
        if link == self.urdf.root and self.robot == "ergo-jr":
            self.lines.append(
                f'{indent}<geom name="{link}_box" type="box" size="0.045 0.045 0.034" '
                f'pos="0 0 -0.034" rgba="0.3 0.3 0.3 1"/>'
            )
        if shown and visual is not None:
            pose = ""
            if any(visual.xyz):
                pose += f' pos="{_v(visual.xyz)}"'
            if any(visual.rpy):
                pose += f' quat="{_v(quat_from_rpy(visual.rpy))}"'
            self.lines.append(
                f'{indent}<geom name="{link}_mesh" class="visual" mesh="{link}"{pose}/>'
            )

    def camera(self, link: str, indent: str, world_quat: Quat) -> None:
        """The robot's camera in ``link`` when it is the one holding it (a MuJoCo camera looks
        along its -z with +y up: its axes are the mount's, turned into the link's frame)."""
        mount = CAMERAS.get(self.robot)
        inertial = self.urdf.links.get(link)
        if mount is None or mount.body != link or inertial is None:
            return
        inv = conjugate(world_quat)
        look = clean(rotate(inv, mount.look))
        up = clean(rotate(inv, mount.up))
        right = clean(cross(look, up))
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

    def body(self, joint: UrdfJoint, depth: int, poses: Frames) -> None:
        indent = "  " * depth
        quat = self.home.joint_quat(joint)
        self.lines.append(
            f'{indent}<body name="{joint.child}" pos="{_v(joint.xyz)}" quat="{_v(quat)}">'
        )
        self.inertial(joint.child, indent + "  ")
        if joint.kind in ("revolute", "continuous"):
            motor = self.motors.get(joint.name, {})
            low, high = motor.get("angle_limit", (-150.0, 150.0))  # motor frame, as pypot's
            servo = servo_params(model_by_name(motor.get("type", "MX-28")))
            home = self.home.home_deg(joint)
            ref = f' ref="{_f(math.radians(home))}"' if home else ""
            self.lines.append(
                f'{indent}  <joint name="{joint.name}" axis="{_v(self.home.axis(joint))}"{ref} '
                f'range="{_f(math.radians(low))} {_f(math.radians(high))}" '
                f'armature="{_f(servo.armature_kgm2)}" frictionloss="{_f(servo.friction_nm)}"/>'
            )
        self.geoms(joint.child, indent + "  ", poses[joint.child][1])
        self.camera(joint.child, indent + "  ", poses[joint.child][1])
        for child in self.urdf.children(joint.child):
            self.body(child, depth + 1, poses)
        self.lines.append(f"{indent}</body>")

    def lowest_point(self, poses: Frames) -> float:
        """Height of the lowest sole below the root at the zero pose (Humanoid)."""
        lows = []
        for link, (pos, _) in poses.items():
            inertial = self.urdf.links.get(link)
            if link.endswith("foot") and inertial is not None:
                com = rotate(poses[link][1], inertial.com)
                lows.append(pos[2] + com[2] - 0.025)
        return min(lows) if lows else 0.0

    def mount(self, poses: Frames) -> tuple[list[str], Vec3, float]:
        """What the robot stands on (world geoms), where its root sits and the lowest height
        its limbs can reach (the table's top or the floor)."""
        if self.style.mount == "table":
            top = TABLE_TOP_M
            stand = [
                f'    <geom name="table" class="world" type="box" size="0.3 0.3 {_f(top / 2)}" '
                f'pos="0 0 {_f(top / 2)}" rgba="0.55 0.4 0.3 1"/>'
            ]
            return stand, (0.0, 0.0, top + 0.068), top
        if self.style.mount == "support":
            top = SUPPORT_TOP_M
            stand = [
                f'    <geom name="support" class="world" type="box" size="0.06 0.06 {_f(top / 2)}" '
                f'pos="0 0 {_f(top / 2)}" rgba="0.3 0.3 0.3 1"/>'
            ]
            return stand, (0.0, 0.0, top), 0.0
        return [], (0.0, 0.0, -self.lowest_point(poses) + 0.002), 0.0

    def meshes(self) -> list[str]:
        """The visual meshes' assets: one per link whose URDF mesh the profile ships."""
        return [
            f'    <mesh name="{link}" file="{visual.mesh}"/>'
            for link, visual in self.urdf.visuals.items()
            if link in self.mesh_links
        ]

    def write(self, assets: dict[str, bytes]) -> str:
        """The MJCF text; its cameras frame the robot over its joints' range, found on the
        model compiled once without them (``assets``: the mesh files)."""
        poses = self.home.world_frames()
        floor_z = self.mount(poses)[2]
        bare = self.text(poses, [])
        follow = self.style.mount == "floor"  # its cameras follow the centre of mass
        cloud = pose_cloud(bare, assets, floor_z, follow_com=follow)
        return self.text(poses, self.cameras(cloud))

    def text(self, poses: Frames, cameras: list[str]) -> str:
        style = self.style
        root = self.urdf.root
        stand, root_pos, _ = self.mount(poses)
        self.lines = []
        out = self.lines
        meshdir = f' meshdir="{MESH_DIR}"' if self.mesh_links else ""
        out += [
            f'<mujoco model="poppy-{self.robot}">',
            f"  <!-- Generated by poppy_core/sim/mjcf.py from {ROBOTS[self.robot]}: "
            "do not edit by hand. -->",
            f'  <compiler angle="radian" autolimits="true"{meshdir}/>',
            '  <option timestep="0.002" integrator="implicitfast"/>',
            self.statistic,
            "  <visual>",
            '    <global offwidth="1280" offheight="960" azimuth="90" elevation="-15"/>',
            '    <headlight ambient="0.3 0.3 0.3" diffuse="0.3 0.3 0.3" '
            'specular="0.05 0.05 0.05"/>',
            '    <quality shadowsize="4096"/>',
            "  </visual>",
            "  <asset>",
            '    <texture name="grid" type="2d" builtin="checker" rgb1="0.78 0.8 0.82" '
            'rgb2="0.68 0.7 0.72" width="256" height="256"/>',
            '    <material name="grid" texture="grid" texrepeat="8 8"/>',
            '    <texture name="sky" type="skybox" builtin="gradient" rgb1="0.93 0.95 0.97" '
            'rgb2="0.62 0.68 0.75" width="64" height="64"/>',
            f'    <material name="shell" rgba="{style.mesh_rgba}" specular="0.2" shininess="0.3"/>',
            *self.meshes(),
            "  </asset>",
            "  <default>",
            '    <geom contype="2" conaffinity="1" condim="3" friction="0.8 0.02 0.001"/>',
            '    <default class="world">',
            '      <geom contype="1" conaffinity="3"/>',
            "    </default>",
            '    <default class="prop">',
            '      <geom contype="1" conaffinity="3"/>',
            "    </default>",
            '    <default class="collision">',
            '      <geom group="3" rgba="0.5 0.5 0.5 0.4"/>',
            "    </default>",
            '    <default class="visual">',
            '      <geom type="mesh" contype="0" conaffinity="0" group="1" density="0" '
            'material="shell"/>',
            "    </default>",
            "  </default>",
            "  <worldbody>",
            '    <light name="sun" pos="0 0 3" dir="0 0 -1" directional="true" '
            'diffuse="0.45 0.45 0.45" specular="0.05 0.05 0.05"/>',
            '    <light name="key" pos="1 -1 2" dir="-1 1 -1.5" diffuse="0.3 0.3 0.3" '
            'specular="0.05 0.05 0.05" castshadow="false"/>',
            '    <geom name="floor" class="world" type="plane" size="3 3 0.05" material="grid"/>',
            *stand,
            *cameras,
        ]
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
    folder = profiles_dir / robot / MESH_DIR
    shipped = frozenset(link for link, v in urdf.visuals.items() if (folder / v.mesh).is_file())
    home = HomePose(urdf, motors, reversed_joints(profiles_dir, robot))
    writer = _Writer(robot, home, shipped)
    assets = {
        urdf.visuals[link].mesh: (folder / urdf.visuals[link].mesh).read_bytes() for link in shipped
    }
    return writer.write(assets)


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
