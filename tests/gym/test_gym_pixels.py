"""The environments' pictures: the robot's camera in the observation, render_mode="rgb_array"."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest

# poppy_core first: it picks MuJoCo's OpenGL backend (MUJOCO_GL) before mujoco is imported
from poppy_core.errors import ConfigError

pytest.importorskip("mujoco")
gym = pytest.importorskip("gymnasium")

from gymnasium.utils.env_checker import check_env  # noqa: E402

from poppy_core.learning.envs import ENVS  # noqa: E402


@pytest.fixture
def pixels_env() -> Iterator[Any]:
    env = gym.make(
        "poppy/ErgoJrPushCube-v0",
        obs_type="pixels_agent_pos",
        render_mode="rgb_array",
        observation_width=96,
        observation_height=72,
    )
    try:
        env.reset(seed=0)
    except ConfigError as exc:
        env.close()
        pytest.skip(f"no OpenGL for offscreen rendering here ({exc}); `make sim-deps`")
    yield env
    env.close()


def test_pixels_come_from_the_robots_camera(pixels_env: Any) -> None:
    obs, _ = pixels_env.reset(seed=0)
    assert set(obs) == {"agent_pos", "agent_vel", "environment_state", "pixels"}
    pixels = obs["pixels"]
    assert pixels.shape == (72, 96, 3) and pixels.dtype == np.uint8
    assert pixels_env.observation_space["pixels"].contains(pixels)
    assert pixels.std() > 5  # a scene, not a blank buffer
    world = pixels_env.unwrapped.world
    assert np.array_equal(pixels, world.render("camera", 96, 72))
    # the camera rides on the head: turning the base changes the picture
    goal = world.goal.astype(np.float32)
    goal[0] = 60.0
    for _ in range(40):
        obs, *_ = pixels_env.step(goal)
    assert np.abs(obs["pixels"].astype(int) - pixels.astype(int)).mean() > 5


def test_render_draws_the_front_view(pixels_env: Any) -> None:
    frame = pixels_env.render()
    assert frame.shape == (480, 640, 3) and frame.dtype == np.uint8
    assert frame.std() > 5


@pytest.mark.parametrize("env_id", sorted(ENVS))
def test_check_env_with_rendering(env_id: str, pixels_env: Any) -> None:
    env = gym.make(env_id, obs_type="pixels_agent_pos", render_mode="rgb_array")
    try:
        check_env(env.unwrapped)
    finally:
        env.close()


def test_make_vec_stacks_pictures(pixels_env: Any) -> None:
    envs = gym.make_vec(
        "poppy/ErgoJrReach-v0",
        num_envs=2,
        vectorization_mode="sync",
        obs_type="pixels_agent_pos",
        observation_width=64,
        observation_height=48,
    )
    try:
        obs, _ = envs.reset(seed=1)
        assert obs["pixels"].shape == (2, 48, 64, 3)
        obs, *_ = envs.step(envs.action_space.sample())
        assert obs["pixels"].shape == (2, 48, 64, 3)
    finally:
        envs.close()


# LeRobot's own reading of a Gymnasium observation (lerobot/envs/utils.py), in its venv
LEROBOT_READS = """
import json, sys
import numpy as np
from lerobot.envs.utils import preprocess_observation
batch = preprocess_observation(dict(np.load(sys.argv[1])))
print(json.dumps({key: [list(value.shape), str(value.dtype)] for key, value in batch.items()}))
"""


def test_lerobot_reads_the_observations(pixels_env: Any, tmp_path: Any) -> None:
    import json
    import os
    import subprocess

    from tests.helpers.lerobot_venv import lerobot_python

    python = lerobot_python()
    envs = gym.make_vec(
        "poppy/ErgoJrPushCube-v0",
        num_envs=2,
        vectorization_mode="sync",
        obs_type="pixels_agent_pos",
        observation_width=64,
        observation_height=48,
    )
    try:
        obs, _ = envs.reset(seed=0)
    finally:
        envs.close()
    np.savez(tmp_path / "obs.npz", **obs)
    env = {key: value for key, value in os.environ.items() if key != "PYTHONPATH"}
    done = subprocess.run(
        [str(python), "-c", LEROBOT_READS, str(tmp_path / "obs.npz")],
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
        env=env,
    )
    assert done.returncode == 0, done.stderr[-3000:]
    shapes = json.loads(done.stdout.strip().splitlines()[-1])
    assert shapes == {
        "observation.image": [[2, 3, 48, 64], "torch.float32"],
        "observation.environment_state": [[2, 9], "torch.float32"],
        "observation.state": [[2, 6], "torch.float32"],
    }
