"""`poppy sim render`: the default camera frames the robot in every pose; a bar shows the frames."""

from __future__ import annotations

import math
import os
import pty
import re
import subprocess
from pathlib import Path

import numpy as np
import pytest

from tests.helpers.cli import POPPY, command_env
from tests.helpers.processes import read_until
from tests.helpers.waiting import scaled

ROOT = Path(__file__).resolve().parents[2]
ASPECT = 640 / 480  # the default render size


def _outside(robot: str, seed: int, view: str = "front") -> list[str]:
    """Geoms of ``robot`` (not the world's) that leave the camera ``view``'s 4:3 frame, over
    its zero pose, its joints at 90% of their limits each way and random poses."""
    import mujoco

    model = mujoco.MjModel.from_xml_path(str(ROOT / "profiles" / robot / "model.xml"))
    data = mujoco.MjData(model)
    camera = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, view)
    tan_v = math.tan(math.radians(float(model.cam_fovy[camera])) / 2)
    hinges = [j for j in range(model.njnt) if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE]
    rng = np.random.default_rng(seed)
    poses: list[dict[int, float]] = [{}]
    for k in (0, 1):
        poses.append({j: 0.9 * float(model.jnt_range[j][k]) for j in hinges})
    for _ in range(20):
        poses.append({j: float(rng.uniform(*model.jnt_range[j])) for j in hinges})
    bad: list[str] = []
    for pose in poses:
        mujoco.mj_resetData(model, data)
        for joint, angle in pose.items():
            data.qpos[model.jnt_qposadr[joint]] = angle
        mujoco.mj_forward(model, data)
        eye = data.cam_xpos[camera]
        axes = data.cam_xmat[camera].reshape(3, 3)  # columns: right, up, back
        for geom in range(model.ngeom):
            if model.geom_bodyid[geom] == 0:
                continue  # floor, table, support
            rel = data.geom_xpos[geom] - eye
            depth = -float(rel @ axes[:, 2])
            reach = float(model.geom_rbound[geom])
            x = abs(float(rel @ axes[:, 0])) + reach
            y = abs(float(rel @ axes[:, 1])) + reach
            if depth <= 0 or x > tan_v * ASPECT * depth or y > tan_v * depth:
                name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, geom)
                bad.append(f"{name} at {'a pose' if pose else 'zero'}")
    return bad


@pytest.mark.parametrize("robot", ["ergo-jr", "torso", "humanoid"])
@pytest.mark.parametrize("view", ["front", "side", "top"])
def test_the_cameras_frame_the_robot_in_every_pose(robot: str, view: str) -> None:
    assert _outside(robot, seed=7, view=view) == []


def test_the_front_camera_sees_the_ergo_jr_large_enough() -> None:
    """Framing the reach does not shrink the robot to a dot: at its zero pose the arm spans a
    fifth of the image's height at least."""
    import mujoco

    model = mujoco.MjModel.from_xml_path(str(ROOT / "profiles" / "ergo-jr" / "model.xml"))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    camera = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, "front")
    tan_v = math.tan(math.radians(float(model.cam_fovy[camera])) / 2)
    axes = data.cam_xmat[camera].reshape(3, 3)
    heights = []
    for body in range(1, model.nbody):
        rel = data.xpos[body] - data.cam_xpos[camera]
        heights.append(float(rel @ axes[:, 1]) / (-float(rel @ axes[:, 2]) * tan_v))
    assert (max(heights) - min(heights)) / 2 > 0.2


def test_a_move_render_shows_its_frames_and_time_left_on_a_terminal(tmp_path: Path) -> None:
    from poppy_core.motion import Move, write_move

    frames = [{"m1": 60.0 * i / 10} for i in range(11)]
    move_file = write_move(Move.from_frames(10, frames), tmp_path / "turn.move.json")
    out = tmp_path / "turn.gif"
    env = dict(os.environ, **command_env({"COLUMNS": "120", "TERM": "xterm"}))
    parent, child = pty.openpty()
    proc = subprocess.Popen(
        [
            *POPPY,
            "sim",
            "render",
            "--move",
            str(move_file),
            "--width",
            "64",
            "--height",
            "48",
            "-o",
            str(out),
        ],
        env=env,
        stdin=child,
        stdout=child,
        stderr=child,
        close_fds=True,
    )
    os.close(child)
    try:
        shown = read_until(parent, None, 240, proc)
        code = proc.wait(timeout=scaled(60))
    finally:
        if proc.poll() is None:
            proc.kill()
        os.close(parent)
    if "cannot render offscreen" in shown:
        pytest.skip(f"no OpenGL backend here: {shown.strip()}")
    assert code == 0, shown
    shown = re.sub(r"\x1b\[[0-9;?]*[A-Za-z]", "", shown)
    counts = re.findall(r"(\d+)/(\d+) frames", shown)
    assert counts, shown
    assert {total for _, total in counts} == {"17"}  # 1 s at 15 fps, the first pose, the last
    assert re.search(r"\d+:\d\d:\d\d left", shown), shown
