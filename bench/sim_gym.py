"""The Gymnasium environments' steps per second, 1 and 8 vectorized, against bare ``mj_step``.

Part of ``python -m bench sim``. Each environment step is one control period (20 ms: 10
physics steps of 2 ms) through poppy's servo model; the bare figure steps the same compiled
model (the env's own ``MjModel``) with ``mj_step`` alone, counted in the same 10-step units.
Random actions (drawn before the clock starts) move every goal far, so the servo ramp runs at
every step: the costliest case of the servo model.

The machine is shared (other programs load it): the single-process figures (bare, one env,
eight in sync mode) count this process's CPU time, which another program's load barely
changes; the async mode's eight processes are timed on the wall clock.
"""

from __future__ import annotations

import time
from typing import Any

from bench.registry import Table
from bench.stats import summary

GYM_IDS = ("poppy/ErgoJrReach-v0", "poppy/ErgoJrPushCube-v0", "poppy/TorsoReach-v0")
GYM_STEPS = 2000  # env steps per measurement (one env); the vectorized ones step 2000 / n times
VECTOR_ENVS = 8


def _actions(space: Any, count: int) -> list[Any]:
    space.seed(0)
    return [space.sample() for _ in range(count)]


def bare_rate(env_id: str) -> float:
    """Env-step equivalents per second of ``mj_step`` alone on the env's model."""
    import gymnasium as gym
    import mujoco

    env = gym.make(env_id)
    try:
        env.reset(seed=0)
        world = env.unwrapped.world  # type: ignore[attr-defined]
        model, data, skip = world.model, world.data, world.frame_skip
        start = time.process_time()
        for _ in range(GYM_STEPS):
            for _ in range(skip):
                mujoco.mj_step(model, data)
        return GYM_STEPS / (time.process_time() - start)
    finally:
        env.close()


def one_env_rate(env_id: str) -> float:
    """Steps per second of ``gymnasium.make(env_id)`` (its wrappers included)."""
    import gymnasium as gym

    env = gym.make(env_id)
    try:
        env.reset(seed=0)
        actions = _actions(env.action_space, GYM_STEPS)
        start = time.process_time()
        for action in actions:
            _, _, terminated, truncated, _ = env.step(action)
            if terminated or truncated:
                env.reset()
        return GYM_STEPS / (time.process_time() - start)
    finally:
        env.close()


def vector_rate(env_id: str, mode: str) -> float:
    """Env steps per second (all envs together) of ``make_vec(num_envs=8)`` in ``mode``: per
    CPU second of this process in sync mode, per wall second in async mode."""
    import gymnasium as gym

    envs = gym.make_vec(env_id, num_envs=VECTOR_ENVS, vectorization_mode=mode)
    try:
        envs.reset(seed=0)
        count = GYM_STEPS // VECTOR_ENVS
        actions = _actions(envs.action_space, count)
        clock = time.process_time if mode == "sync" else time.perf_counter
        start = clock()
        for action in actions:
            envs.step(action)  # autoreset: ended envs start again by themselves
        return count * VECTOR_ENVS / (clock() - start)
    finally:
        envs.close()


def gym_table(repeat: int) -> tuple[Table, dict[str, Any]]:
    """The table of every env's rates (medians of ``repeat`` rounds, the four measured in
    turns within a round) and the raw figures."""
    import poppy_core.learning.envs  # noqa: F401 (registers the ids)

    raw: dict[str, Any] = {}
    rows: list[list[str]] = []
    for env_id in GYM_IDS:
        rounds = [
            {
                "bare": bare_rate(env_id),
                "one": one_env_rate(env_id),
                "sync8": vector_rate(env_id, "sync"),
                "async8": vector_rate(env_id, "async"),
            }
            for _ in range(repeat)
        ]
        raw[env_id] = rounds
        median = {key: summary([r[key] for r in rounds])["median"] for key in rounds[0]}
        ratio = summary([r["one"] / r["bare"] for r in rounds])["median"]
        rows.append(
            [
                env_id,
                f"{median['bare']:,.0f}",
                f"{median['one']:,.0f}",
                f"{ratio:.2f}",
                f"{median['sync8']:,.0f}",
                f"{median['async8']:,.0f}",
            ]
        )
    table = Table(
        "Gymnasium environments: env steps per CPU second (one step = 20 ms simulated)",
        [
            "environment",
            "bare mj_step (×10)",
            "1 env",
            "1 env / bare",
            f"{VECTOR_ENVS} envs, sync",
            f"{VECTOR_ENVS} envs, async (wall clock)",
        ],
        rows,
    )
    return table, raw
