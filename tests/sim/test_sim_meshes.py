"""The robots' meshes sit where the URDF puts each link: renders of each creature in a few
postures, their silhouettes checked against the URDF's frames and against reference images."""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from poppy_core.errors import ConfigError
from poppy_core.sim.home_pose import reversed_joints
from poppy_core.sim.mjcf import ROBOTS
from poppy_core.sim.urdf import parse_urdf

mujoco = pytest.importorskip("mujoco")

pytestmark = pytest.mark.gl  # renders with OpenGL in the test process

ROOT = Path(__file__).resolve().parents[2]
PROFILES = ROOT / "profiles"
REFERENCES = Path(__file__).resolve().parent / "data" / "silhouettes"
WIDTH, HEIGHT = 320, 240
NEAR_PX = 2.5  # a link's origin projects inside the silhouette or this close to it
MIN_IOU = 0.97  # a render's silhouette against its reference (set POPPY_UPDATE_SILHOUETTES=1)
# motor angles as shares of each joint's range: the zero pose and two bent ones
POSTURES = {"zero": 0.0, "bent": 0.35, "other way": -0.35}


@pytest.fixture(scope="module", autouse=True)
def _gl() -> None:
    from poppy_core.sim.gl import check_offscreen_gl

    try:
        check_offscreen_gl()
    except ConfigError as exc:
        pytest.skip(f"no offscreen OpenGL here ({exc}); `make sim-deps`")


def _model(robot: str) -> Any:
    return mujoco.MjModel.from_xml_path(str(PROFILES / robot / "model.xml"))


def _pose(model: Any, data: Any, share: float) -> dict[str, float]:
    """Put every hinge at ``share`` of its range from its middle; the motor angles (rad)."""
    mujoco.mj_resetData(model, data)
    angles = {}
    for j in range(model.njnt):
        if int(model.jnt_type[j]) != int(mujoco.mjtJoint.mjJNT_HINGE):
            continue
        low, high = (float(v) for v in model.jnt_range[j])
        angle = min(max(0.0, low), high) + share * (high - low) / 2
        angle = min(max(angle, low), high)
        data.qpos[model.jnt_qposadr[j]] = angle
        angles[mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j)] = angle
    mujoco.mj_forward(model, data)  # the cameras too (the Humanoid's follow its centre of mass)
    return angles


def _silhouette(model: Any, data: Any, camera: str) -> np.ndarray:
    """Pixels (HEIGHT, WIDTH) showing a visual mesh of the robot."""
    meshes = {
        g
        for g in range(model.ngeom)
        if int(model.geom_type[g]) == int(mujoco.mjtGeom.mjGEOM_MESH) and model.geom_bodyid[g] != 0
    }
    renderer = mujoco.Renderer(model, HEIGHT, WIDTH)
    try:
        renderer.enable_segmentation_rendering()
        renderer.update_scene(data, camera=camera)
        seg = renderer.render()
    finally:
        renderer.close()
    ids, kinds = seg[:, :, 0], seg[:, :, 1]
    is_geom = kinds == int(mujoco.mjtObj.mjOBJ_GEOM)
    return is_geom & np.isin(ids, sorted(meshes))


def _rotation(axis: tuple[float, float, float], angle: float) -> np.ndarray:
    x, y, z = np.asarray(axis) / np.linalg.norm(axis)
    c, s, t = math.cos(angle), math.sin(angle), 1 - math.cos(angle)
    return np.array(
        [
            [t * x * x + c, t * x * y - s * z, t * x * z + s * y],
            [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
            [t * x * z - s * y, t * y * z + s * x, t * z * z + c],
        ]
    )


def _urdf_origins(robot: str, model: Any, data: Any, motors: dict[str, float]) -> dict[str, Any]:
    """Every link's origin in the world by the URDF's own chain (its joint origins and axes at
    the URDF angle of each motor), from where the model puts the root link."""
    urdf = parse_urdf(PROFILES / robot / ROBOTS[robot])
    flipped = reversed_joints(PROFILES, robot)
    root = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, urdf.root)
    root_rot = np.zeros(9)
    mujoco.mju_quat2Mat(root_rot, data.xquat[root])
    frames = {urdf.root: (data.xpos[root].copy(), root_rot.reshape(3, 3))}
    pending = [urdf.root]
    while pending:
        link = pending.pop()
        pos, rot = frames[link]
        for joint in urdf.children(link):
            roll, pitch, yaw = joint.rpy
            base = (
                _rotation((0, 0, 1), yaw) @ _rotation((0, 1, 0), pitch) @ _rotation((1, 0, 0), roll)
            )
            angle = motors.get(joint.name, 0.0) * (-1.0 if joint.name in flipped else 1.0)
            turn = _rotation(joint.axis, angle) if joint.kind != "fixed" else np.eye(3)
            frames[joint.child] = (pos + rot @ np.asarray(joint.xyz), rot @ base @ turn)
            pending.append(joint.child)
    return {link: pos for link, (pos, _) in frames.items()}


def _project(model: Any, data: Any, camera: str, point: np.ndarray) -> tuple[float, float]:
    cam = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, camera)
    axes = data.cam_xmat[cam].reshape(3, 3)  # columns: right, up, back
    rel = point - data.cam_xpos[cam]
    depth = -float(rel @ axes[:, 2])
    focal = (HEIGHT / 2) / math.tan(math.radians(float(model.cam_fovy[cam])) / 2)
    return WIDTH / 2 + focal * float(rel @ axes[:, 0]) / depth, HEIGHT / 2 - focal * float(
        rel @ axes[:, 1]
    ) / depth


def _distance_px(mask: np.ndarray, u: float, v: float) -> float:
    rows, cols = np.nonzero(mask)
    if len(rows) == 0:
        return math.inf
    # pixel (col, row) covers [col, col+1) × [row, row+1): its centre is at +0.5
    return float(np.min(np.hypot(cols + 0.5 - u, rows + 0.5 - v)))


@pytest.mark.parametrize("robot", list(ROBOTS))
@pytest.mark.parametrize("camera", ["front", "side"])
def test_every_link_origin_of_the_urdf_falls_on_the_robots_silhouette(
    robot: str, camera: str
) -> None:
    model = _model(robot)
    data = mujoco.MjData(model)
    far: list[str] = []
    for posture, share in POSTURES.items():
        motors = _pose(model, data, share)
        mask = _silhouette(model, data, camera)
        assert mask.mean() > 0.005, f"{robot} {posture}: no mesh in view"
        for link, origin in _urdf_origins(robot, model, data, motors).items():
            u, v = _project(model, data, camera, origin)
            gap = _distance_px(mask, u, v)
            if gap > NEAR_PX:
                far.append(f"{link} ({posture}): {gap:.1f} px off")
    assert far == []


def _iou(a: np.ndarray, b: np.ndarray) -> float:
    return float((a & b).sum()) / max(1, int((a | b).sum()))


@pytest.mark.parametrize("robot", list(ROBOTS))
def test_the_silhouettes_match_the_reference_images(robot: str) -> None:
    from PIL import Image

    model = _model(robot)
    data = mujoco.MjData(model)
    for posture, share in (("zero", 0.0), ("bent", 0.35)):
        _pose(model, data, share)
        for camera in ("front", "side"):
            mask = _silhouette(model, data, camera)
            path = REFERENCES / f"{robot}-{posture}-{camera}.png"
            if os.environ.get("POPPY_UPDATE_SILHOUETTES") == "1":
                path.parent.mkdir(parents=True, exist_ok=True)
                Image.fromarray(mask.astype(np.uint8) * 255).convert("1").save(path, optimize=True)
            reference = np.asarray(Image.open(path).convert("L")) > 127
            iou = _iou(mask, reference)
            assert iou >= MIN_IOU, f"{path.name}: {iou:.3f} of the reference"


@pytest.mark.parametrize("robot", list(ROBOTS))
def test_the_physics_steps_without_the_meshes_and_renders_draw_them(robot: str) -> None:
    from poppy_core.sim.world import Simulation

    sim = Simulation.from_file(PROFILES / robot / "model.xml")
    try:
        mesh = int(mujoco.mjtGeom.mjGEOM_MESH)
        stepped = [int(t) for t in sim.model.geom_type]
        drawn = [int(t) for t in sim.view_model.geom_type]
        assert mesh not in stepped and drawn.count(mesh) >= 7
        assert (sim.model.nbody, sim.model.njnt, sim.model.ncam) == (
            sim.view_model.nbody,
            sim.view_model.njnt,
            sim.view_model.ncam,
        )
        sim.add_object("cube", "box", (0.3, 0.3, 0.9), size=0.02, mass=0.05)
        assert mesh not in [int(t) for t in sim.model.geom_type]
        sim.advance(0.2)
        with sim.lock:
            view = sim.view()
            box = mujoco.mj_name2id(sim.view_model, mujoco.mjtObj.mjOBJ_BODY, "box")
            free = mujoco.mj_name2id(sim.model, mujoco.mjtObj.mjOBJ_JOINT, "box_free")
            address = int(sim.model.jnt_qposadr[free])
            where = [float(v) for v in sim.data.qpos[address : address + 3]]
            assert [float(v) for v in view.xpos[box]] == where  # drawn where the physics has it
    finally:
        sim.close()
