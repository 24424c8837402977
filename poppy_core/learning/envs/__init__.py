"""Gymnasium environments on poppy's MuJoCo simulation; importing this registers their ids.

``gymnasium.make("poppy_core.learning.envs:poppy/ErgoJrReach-v0")`` imports it on the way
(Gymnasium's ``module:id``); after ``import poppy_core.learning.envs``,
``gymnasium.make("poppy/ErgoJrReach-v0")`` does. Gymnasium 1.x loads no plugin entry points,
so an import is what registers them (see docs/learning.md).
"""

from __future__ import annotations

from typing import Any

from poppy_core.extras import require

require("gymnasium", "mujoco", extra="gym")

from gymnasium.envs.registration import register, registry  # noqa: E402

REACH = "poppy_core.learning.envs.reach:ReachEnv"
PUSH = "poppy_core.learning.envs.push:PushCubeEnv"

# id -> (entry point, max_episode_steps, keyword arguments); 50 steps a simulated second
ENVS: dict[str, tuple[str, int, dict[str, Any]]] = {
    "poppy/ErgoJrReach-v0": (REACH, 200, {"robot": "ergo-jr", "chain": "chain"}),
    "poppy/ErgoJrPushCube-v0": (PUSH, 400, {"robot": "ergo-jr", "chain": "chain"}),
    "poppy/TorsoReach-v0": (
        REACH,
        200,
        {"robot": "torso", "chain": "l_arm_chain", "success_m": 0.03},
    ),
}


def register_envs() -> None:
    """Register the ids of ``ENVS`` with Gymnasium (those not registered yet)."""
    for env_id, (entry_point, steps, kwargs) in ENVS.items():
        if env_id not in registry:
            register(id=env_id, entry_point=entry_point, max_episode_steps=steps, kwargs=kwargs)


register_envs()
