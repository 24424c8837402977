"""The Gymnasium environments: check_env, spaces, seeding, rewards, max_episode_steps, make_vec."""

from __future__ import annotations

import tomllib
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

# poppy_core first: it picks MuJoCo's OpenGL backend (MUJOCO_GL) before mujoco is imported
from poppy_core.errors import ArgumentError

pytest.importorskip("mujoco")
gym = pytest.importorskip("gymnasium")

from gymnasium.utils.env_checker import check_env  # noqa: E402

from poppy_core.learning.envs import ENVS  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
IDS = sorted(ENVS)
MOTORS = {"poppy/ErgoJrReach-v0": 6, "poppy/ErgoJrPushCube-v0": 6, "poppy/TorsoReach-v0": 13}
STATE = {"poppy/ErgoJrReach-v0": 6, "poppy/ErgoJrPushCube-v0": 9, "poppy/TorsoReach-v0": 6}


@pytest.fixture
def make() -> Iterator[Any]:
    made: list[Any] = []

    def build(env_id: str, **kwargs: Any) -> Any:
        env = gym.make(env_id, **kwargs)
        made.append(env)
        return env

    yield build
    for env in made:
        env.close()


def rollout(env: Any, seed: int, steps: int) -> list[tuple[Any, ...]]:
    """Observations and rewards of ``steps`` steps of actions drawn from ``seed``."""
    obs, _ = env.reset(seed=seed)
    env.action_space.seed(seed)
    out = [tuple(np.array(v) for v in obs.values())]
    for _ in range(steps):
        obs, reward, *_ = env.step(env.action_space.sample())
        out.append((*(np.array(v) for v in obs.values()), reward))
    return out


@pytest.mark.parametrize("env_id", IDS)
def test_passes_gymnasium_check_env(env_id: str, make: Any) -> None:
    # rendering is checked in test_gym_pixels.py (OpenGL, a process of its own)
    check_env(make(env_id).unwrapped, skip_render_check=True)


@pytest.mark.parametrize("env_id", IDS)
def test_spaces_are_degrees_per_motor_and_a_dict_of_state(env_id: str, make: Any) -> None:
    env = make(env_id)
    count = MOTORS[env_id]
    world = env.unwrapped.world
    assert env.action_space.shape == (count,)
    assert np.array_equal(env.action_space.low, world.low.astype(np.float32))
    assert np.array_equal(env.action_space.high, world.high.astype(np.float32))
    obs, info = env.reset(seed=0)
    assert set(obs) == {"agent_pos", "agent_vel", "environment_state"}
    assert obs["agent_pos"].shape == obs["agent_vel"].shape == (count,)
    assert obs["environment_state"].shape == (STATE[env_id],)
    assert info["is_success"] is False
    assert env.spec.max_episode_steps == ENVS[env_id][1]


def test_the_limits_are_the_profiles_and_the_model_is_poppy_sims() -> None:
    from poppy_core.learning.envs.reach import ReachEnv
    from poppy_core.robot.profiles import load_profile
    from poppy_core.sim.world import Simulation

    env = ReachEnv("ergo-jr")
    try:
        config = load_profile("ergo-jr")
        expected = [config.motors[name].user_angle_limit for name in env.motor_names]
        assert [tuple(pair) for pair in zip(env.world.low, env.world.high, strict=True)] == expected
        sim = Simulation.from_file(ROOT / "profiles" / "ergo-jr" / "model.xml")
        model = env.world.model
        assert (model.nbody, model.njnt, model.nu) == (
            sim.model.nbody,
            sim.model.njnt,
            sim.model.nu,
        )
        assert np.array_equal(model.jnt_range, sim.model.jnt_range)
        assert np.array_equal(model.actuator_forcerange, sim.model.actuator_forcerange)
        sim.close()
    finally:
        env.close()


def test_the_push_task_adds_one_cube_to_the_same_model(make: Any) -> None:
    reach = make("poppy/ErgoJrReach-v0").unwrapped.world.model
    push = make("poppy/ErgoJrPushCube-v0").unwrapped.world.model
    assert push.nbody == reach.nbody + 1
    assert push.njnt == reach.njnt + 1  # the cube's free joint
    assert push.nu == reach.nu


@pytest.mark.parametrize("env_id", IDS)
def test_a_seed_gives_the_same_episode(env_id: str, make: Any) -> None:
    first, second, other = make(env_id), make(env_id), make(env_id)
    a, b = rollout(first, 7, 15), rollout(second, 7, 15)
    for one, two in zip(a, b, strict=True):
        for x, y in zip(one, two, strict=True):
            assert np.array_equal(x, y)
    c = rollout(other, 8, 0)
    assert not np.array_equal(a[0][2], c[0][2])  # another seed, another task
    again = rollout(first, 7, 15)  # the same env, reset with the seed again
    for one, two in zip(a, again, strict=True):
        for x, y in zip(one, two, strict=True):
            assert np.array_equal(x, y)


@pytest.mark.parametrize("env_id", ["poppy/ErgoJrReach-v0", "poppy/TorsoReach-v0"])
def test_reaching_the_target_gives_the_highest_reward(env_id: str, make: Any) -> None:
    env = make(env_id)
    inner = env.unwrapped
    _, info = env.reset(seed=3)
    start = -info["distance_m"]
    target_pose = inner.target_pose.astype(np.float32)
    rewards, terminated = [], False
    for _ in range(100):
        _, reward, terminated, _, info = env.step(target_pose)
        rewards.append(reward)
        if terminated:
            break
    assert terminated and info["is_success"], info
    assert rewards[-1] == max(rewards) > start
    assert -inner.success_m < rewards[-1] <= 0.0
    # any other pose scores lower
    env.reset(seed=3)
    env.action_space.seed(3)
    for _ in range(20):
        _, reward, *_ = env.step(env.action_space.sample())
        assert reward < rewards[-1]


def test_the_reward_is_the_tip_where_mujoco_has_it(make: Any) -> None:
    import mujoco

    env = make("poppy/ErgoJrReach-v0")
    obs, _ = env.reset(seed=1)
    for _ in range(10):
        obs, *_ = env.step(env.unwrapped.target_pose.astype(np.float32))
    world = env.unwrapped.world
    chain = world.chains["chain"]
    mujoco.mj_forward(world.model, world.data)
    tip = mujoco.mj_name2id(world.model, mujoco.mjtObj.mjOBJ_BODY, "tip")
    where = world.data.xpos[tip] + world.data.xmat[tip].reshape(3, 3) @ chain.tip
    base, _ = world.base_frame(chain)
    assert np.allclose(obs["environment_state"][3:], where - base, atol=1e-4)


def test_the_cube_at_the_goal_scores_more_than_where_it_starts(make: Any) -> None:
    env = make("poppy/ErgoJrPushCube-v0")
    inner = env.unwrapped
    _, info = env.reset(seed=2)
    hold = inner.world.goal.astype(np.float32)
    _, at_start, terminated, _, info = env.step(hold)
    assert not terminated and info["cube_to_goal_m"] > inner.success_m
    inner.world.place("cube", inner.goal)
    _, at_goal, terminated, _, info = env.step(hold)
    assert terminated and info["is_success"]
    assert at_goal > at_start


def test_delta_actions_move_the_last_goals(make: Any) -> None:
    env = make("poppy/ErgoJrReach-v0", action_type="delta", max_delta_deg=5.0)
    env.reset(seed=0)
    assert env.action_space.shape == (6,)
    assert np.all(env.action_space.high == 5.0)
    start = env.unwrapped.world.goal.copy()
    step = np.zeros(6, dtype=np.float32)
    step[0] = 5.0
    for _ in range(4):
        obs, *_ = env.step(step)
    assert np.allclose(env.unwrapped.world.goal - start, [20.0, 0, 0, 0, 0, 0])
    for _ in range(30):
        obs, *_ = env.step(np.zeros(6, dtype=np.float32))
    assert abs(float(obs["agent_pos"][0]) - 20.0) < 2.0


def test_goals_past_the_limits_stop_at_them(make: Any) -> None:
    env = make("poppy/ErgoJrReach-v0", action_type="delta", max_delta_deg=10.0)
    env.reset(seed=0)
    step = np.full(6, 10.0, dtype=np.float32)
    for _ in range(40):
        env.step(step)
    assert np.array_equal(env.unwrapped.world.goal, env.unwrapped.world.high)


def test_max_episode_steps_truncates(make: Any) -> None:
    env = make("poppy/ErgoJrReach-v0", max_episode_steps=3)
    env.reset(seed=0)
    hold = env.unwrapped.world.goal.astype(np.float32)
    flags = [env.step(hold)[3] for _ in range(3)]
    assert flags == [False, False, True]


def test_make_vec_stacks_the_envs(make: Any) -> None:
    envs = gym.make_vec("poppy/ErgoJrPushCube-v0", num_envs=3, vectorization_mode="sync")
    try:
        obs, _ = envs.reset(seed=5)
        assert obs["agent_pos"].shape == (3, 6)
        assert obs["environment_state"].shape == (3, 9)
        assert not np.array_equal(obs["environment_state"][0], obs["environment_state"][1])
        obs, reward, terminated, truncated, _ = envs.step(envs.action_space.sample())
        assert envs.action_space.shape == (3, 6)
        assert reward.shape == terminated.shape == truncated.shape == (3,)
        assert obs["agent_vel"].shape == (3, 6)
    finally:
        envs.close()


def test_make_vec_async_runs_each_env_in_a_process_of_its_own() -> None:
    envs = gym.make_vec("poppy/ErgoJrReach-v0", num_envs=2, vectorization_mode="async")
    try:
        obs, _ = envs.reset(seed=4)
        assert obs["agent_pos"].shape == (2, 6)
        _, reward, *_ = envs.step(envs.action_space.sample())
        assert reward.shape == (2,)
    finally:
        envs.close()


def test_goals_are_reached_at_the_servos_speed(make: Any) -> None:
    """A far goal is followed at the servo's no-load speed (the sim's servo model), not at once."""
    from poppy_core.models import model_by_name

    env = make("poppy/ErgoJrReach-v0")
    env.reset(seed=0)
    world = env.unwrapped.world
    speed_dps = model_by_name("XL-320").no_load_speed_dps
    goal = world.goal.astype(np.float32)
    goal[0] = 90.0
    obs, *_ = env.step(goal)
    assert 0.0 < obs["agent_pos"][0] <= speed_dps * world.control_period_s + 1.0
    for _ in range(50):
        obs, *_ = env.step(goal)
    assert abs(float(obs["agent_pos"][0]) - 90.0) < 2.0


def test_the_module_id_form_registers_on_the_way() -> None:
    env = gym.make("poppy_core.learning.envs:poppy/TorsoReach-v0")
    try:
        assert env.unwrapped.motor_names[:3] == ("abs_z", "bust_y", "bust_x")
    finally:
        env.close()


@pytest.mark.parametrize(
    ("kwargs", "words"),
    [
        ({"obs_type": "pixels"}, "obs_type must be one of state, pixels_agent_pos"),
        ({"action_type": "velocity"}, "action_type must be one of absolute, delta"),
        ({"render_mode": "human"}, "render_mode must be one of rgb_array"),
        ({"chain": "leg"}, "the robot has no chain 'leg' (chains: chain)"),
        ({"control_hz": 0}, "control_hz and max_delta_deg must be positive"),
        ({"camera": "eye"}, "camera must be one of front, side, top, camera, not 'eye'"),
    ],
)
def test_bad_options_are_one_clear_line(kwargs: dict[str, Any], words: str) -> None:
    from poppy_core.learning.envs.reach import ReachEnv

    # the class itself: gymnasium.make turns render_mode="human" into its own window wrapper
    with pytest.raises(ArgumentError) as caught:
        ReachEnv("ergo-jr", **kwargs)
    assert words in str(caught.value) and "\n" not in str(caught.value)


def test_an_action_of_the_wrong_shape_is_refused(make: Any) -> None:
    env = make("poppy/ErgoJrReach-v0", disable_env_checker=True)
    env.reset(seed=0)
    with pytest.raises(ArgumentError, match="an action is 6 finite numbers"):
        env.step(np.zeros(5, dtype=np.float32))


def test_the_gym_extra_brings_gymnasium_and_the_tests_have_it() -> None:
    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    extras = project["optional-dependencies"]
    assert any(d.startswith("gymnasium>=1") for d in extras["gym"])
    assert any(d.startswith("gymnasium>=1") for d in extras["test"])
    assert "gym" in extras["all"][0]
