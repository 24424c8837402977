"""PushCubeEnv: the Ergo Jr pushes a cube on its table to a goal mark."""

from __future__ import annotations

import math
from typing import Any, ClassVar

import numpy as np

from poppy_core.errors import ArgumentError
from poppy_core.learning.envs.poppy_env import PoppyEnv
from poppy_core.learning.envs.reach import ChainTip
from poppy_core.sim.looks import TABLE_TOP_M
from poppy_core.sim.objects import ObjectSpec

CUBE = "cube"
CUBE_HALF_M = 0.015  # a 3 cm cube
CUBE_MASS_KG = 0.02
RADIUS_M = (0.10, 0.15)  # where the cube starts: this far from the base's axis...
BEARING_DEG = (-60.0, 60.0)  # ...at this bearing from the robot's front (+x)
TURN_DEG = (15.0, 30.0)  # the goal: the cube's place turned this much about the base's axis
TIP_WEIGHT = 0.2  # the reward's pull of the tip toward the cube (shaping), per metre


class PushCubeEnv(PoppyEnv):
    """Push a cube (3 cm, 20 g) on the table to a goal: the cube's start turned 15-30° about
    the base's axis, either way (a push across the robot's front).

    The cube is added to the profile's model with MjSpec (``Simulation.add_object``).
    ``environment_state``: the cube, the goal and the tip (x, y, z each, metres, the chain's
    base frame). Reward: minus the cube's distance to the goal on the table (m), minus
    ``TIP_WEIGHT`` times the tip's distance to the cube; the episode ends (terminated) when the
    cube is within ``success_m`` of the goal, with ``info["is_success"]``.

    Args:
        robot: the profile (one standing on the table: ``ergo-jr``).
        chain: the chain whose tip pushes (None: the profile's first).
        success_m: the cube's distance to the goal counted as there.
        **options: ``PoppyEnv``'s.
    """

    objects: ClassVar[tuple[ObjectSpec, ...]] = (
        ObjectSpec.make(
            "cube", CUBE, (RADIUS_M[0], 0.0, TABLE_TOP_M + CUBE_HALF_M), CUBE_HALF_M, CUBE_MASS_KG
        ),
    )
    state_size: ClassVar[int] = 9

    def __init__(
        self,
        robot: str = "ergo-jr",
        chain: str | None = None,
        success_m: float = 0.02,
        **options: Any,
    ) -> None:
        super().__init__(robot, **options)
        self.tip = ChainTip(self.world, chain)
        if not success_m > 0:
            raise ArgumentError("success_m must be positive")
        self.success_m = float(success_m)
        self._base, self._rotation = self.world.base_frame(self.tip.chain)
        self.cube_start = np.zeros(3)
        self.goal = np.zeros(3)
        self.cube_now = np.zeros(3)  # world frame
        self.tip_now = np.zeros(3)  # the chain's base frame

    def _in_base(self, world_point: np.ndarray) -> np.ndarray:
        return np.asarray(self._rotation.T @ (world_point - self._base))

    def _start(self, rng: np.random.Generator) -> np.ndarray:
        radius = rng.uniform(*RADIUS_M)
        bearing = math.radians(rng.uniform(*BEARING_DEG))
        turn = math.radians(rng.uniform(*TURN_DEG)) * rng.choice([-1.0, 1.0])
        z = TABLE_TOP_M + CUBE_HALF_M
        x0, y0 = float(self._base[0]), float(self._base[1])
        self.cube_start = np.array(
            [x0 + radius * math.cos(bearing), y0 + radius * math.sin(bearing), z]
        )
        goal = bearing + turn
        self.goal = np.array([x0 + radius * math.cos(goal), y0 + radius * math.sin(goal), z])
        return self.world.home()

    def _arrange(self) -> None:
        self.world.place(CUBE, self.cube_start)

    def _sense(self) -> None:
        self.cube_now = self.world.object_position(CUBE)
        self.tip_now = self.tip.of(self.pose)

    def _environment_state(self) -> np.ndarray:
        cube = self._in_base(self.cube_now)
        return np.concatenate([cube, self._in_base(self.goal), self.tip_now])

    def _evaluate(self) -> tuple[float, bool, dict[str, Any]]:
        left = float(np.linalg.norm((self.cube_now - self.goal)[:2]))
        reach = float(np.linalg.norm(self.tip_now - self._in_base(self.cube_now)))
        success = left < self.success_m
        info = {"cube_to_goal_m": left, "tip_to_cube_m": reach, "is_success": success}
        return -left - TIP_WEIGHT * reach, success, info
