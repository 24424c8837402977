"""ReachEnv: bring the tip of one of the robot's chains to a target point (Ergo Jr, Torso)."""

from __future__ import annotations

from typing import Any, ClassVar

import numpy as np

from poppy_core.errors import ArgumentError
from poppy_core.learning.envs.poppy_env import PoppyEnv
from poppy_core.learning.envs.servo_world import ServoWorld


class ChainTip:
    """Where a chain's tip is, by forward kinematics of the world's joint angles (metres, in the
    chain's base frame: the robot's base link, fixed in the world)."""

    def __init__(self, world: ServoWorld, chain: str | None = None) -> None:
        if chain is None and world.chains:
            chain = next(iter(world.chains))
        if chain not in world.chains:
            known = ", ".join(world.chains) or "none"
            raise ArgumentError(f"the robot has no chain {chain!r} (chains: {known})")
        self.chain = world.chains[str(chain)]
        self._index = [world.names.index(name) for name in self.chain.names]

    def of(self, pose_deg: np.ndarray) -> np.ndarray:
        """The tip's position for a whole pose (degrees, the world's motor order)."""
        angles = np.asarray(pose_deg)[self._index]
        pose = self.chain.kinematics.pose(self.chain.to_model(angles))
        return np.asarray(pose[:3, 3])


class ReachEnv(PoppyEnv):
    """Reach a target: a point the chain's tip reaches in a pose drawn at random within the
    motors' limits (so every target is reachable).

    ``environment_state``: the target and the tip (x, y, z each, metres, the chain's base
    frame). Reward: minus the tip's distance to the target (m), 0 at best; an episode ends
    (terminated) when the tip is within ``success_m``, with ``info["is_success"]``.

    Args:
        robot: the profile.
        chain: the chain whose tip reaches (the profile's ``kinematics.chains``; None: its
            first).
        success_m: the distance counted as reached.
        target_spread: how far from the start pose (0..1 of the way to the limits) the
            target's pose is drawn.
        **options: ``PoppyEnv``'s (obs_type, action_type, render_mode, control_hz...).
    """

    state_size: ClassVar[int] = 6

    def __init__(
        self,
        robot: str = "ergo-jr",
        chain: str | None = None,
        success_m: float = 0.02,
        target_spread: float = 0.5,
        **options: Any,
    ) -> None:
        super().__init__(robot, **options)
        self.tip = ChainTip(self.world, chain)
        if not success_m > 0 or not 0 < target_spread <= 1:
            raise ArgumentError("success_m must be positive and target_spread within (0, 1]")
        self.success_m = float(success_m)
        self.target_spread = float(target_spread)
        self.target = np.zeros(3)
        self.target_pose = self.world.home()
        self.tip_now = np.zeros(3)

    def _start(self, rng: np.random.Generator) -> np.ndarray:
        home = self.world.home()
        drawn = rng.uniform(self.world.low, self.world.high)
        self.target_pose = home + self.target_spread * (drawn - home)
        self.target = self.tip.of(self.target_pose)
        return home

    def _sense(self) -> None:
        self.tip_now = self.tip.of(self.pose)

    def _environment_state(self) -> np.ndarray:
        return np.concatenate([self.target, self.tip_now])

    def _evaluate(self) -> tuple[float, bool, dict[str, Any]]:
        distance = float(np.linalg.norm(self.tip_now - self.target))
        success = distance < self.success_m
        return -distance, success, {"distance_m": distance, "is_success": success}
