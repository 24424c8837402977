"""Train a linear policy on poppy/ErgoJrReach-v0 by random search (numpy only, under a minute).

Run: ``python docs/examples/gym_random_search.py``. The policy turns the observation into
delta actions (degrees per step): ``action = W @ (target - tip)``, the target's offset from
the tip in cm (``environment_state``). Each round tries ``W`` nudged both ways along a few
random directions on the same seeds and moves it toward the better side of each (basic
random search, Mania et al. 2018). Measured here: the mean return over the four seeds is
-11.0 for the robot that stays still (round 0), between -3.2 and -6.7 from round 3 on (20
rounds, 17 s of CPU); random search is noisy, the rounds do not improve one by one.
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np

import poppy_core.learning.envs  # noqa: F401 (registers the poppy/ ids)

ROUNDS = 20
DIRECTIONS = 4
SEEDS = (0, 1, 2, 3)
EPISODE_STEPS = 60
STEP_SIZE = 0.1
NOISE = 0.5


def features(obs: dict[str, np.ndarray]) -> np.ndarray:
    target, tip = obs["environment_state"][:3], obs["environment_state"][3:]
    return (target - tip) * 100.0


def episode_return(env: gym.Env, weights: np.ndarray, seed: int) -> float:
    obs, _ = env.reset(seed=seed)
    total = 0.0
    for _ in range(EPISODE_STEPS):
        obs, reward, terminated, truncated, _ = env.step(
            np.clip(weights @ features(obs), -10, 10).astype(np.float32)
        )
        total += float(reward)
        if terminated or truncated:
            break
    return total


def main() -> None:
    env = gym.make("poppy/ErgoJrReach-v0", action_type="delta")
    rng = np.random.default_rng(0)
    weights = np.zeros((6, 3))  # a robot that stays still
    print(f"round  0: mean return {np.mean([episode_return(env, weights, s) for s in SEEDS]):.2f}")
    for round_ in range(ROUNDS):
        step = np.zeros_like(weights)
        for _ in range(DIRECTIONS):
            direction = rng.standard_normal(weights.shape)
            plus = np.mean([episode_return(env, weights + NOISE * direction, s) for s in SEEDS])
            minus = np.mean([episode_return(env, weights - NOISE * direction, s) for s in SEEDS])
            step += (plus - minus) / (2 * NOISE * DIRECTIONS) * direction
        weights += STEP_SIZE * step
        score = np.mean([episode_return(env, weights, s) for s in SEEDS])
        print(f"round {round_ + 1:2d}: mean return {score:.2f}")
    env.close()


if __name__ == "__main__":
    main()
