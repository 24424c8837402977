"""``head_follow``: the tip of a simulated Ergo Jr follows an object of its MuJoCo scene.

The Poppy documentation's Ergo Jr has a ``head_follow`` primitive: "The robot's head, or
end-point, follows a marker from the simulator". Here the marker is an object added to the
MuJoCo scene (``robot.simulation.add_object``) and moved by the user; at each update the chain
is solved for a point above it (``offset``, in the chain's base frame) and the motors glide
there. Beyond the arm's reach the tip goes to the nearest point it reaches.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from typing import TYPE_CHECKING, ClassVar

import numpy as np

from poppy_core.motion import LoopPrimitive
from poppy_core.motion.cartesian import RobotChain

if TYPE_CHECKING:
    from poppy_core.robot import Robot

logger = logging.getLogger(__name__)

HEAD_FOLLOW_HZ = 10.0
MOVED_M = 0.002
"""The object must move this much for the arm to follow (no jitter on a still object)."""


class HeadFollow(LoopPrimitive):
    """Keep the chain's tip ``offset`` metres from an object of the simulation.

    Args:
        robot: a robot simulated with MuJoCo (``robot.simulation``) with the chain attached.
        chain: the name of the chain whose tip follows.
        target: the object to follow; None follows the object added last.
        offset: ``[x, y, z]`` from the object to the tip, in the chain's base frame (m).
        freq: updates per second.
    """

    properties: ClassVar[Sequence[str]] = ("target", "offset", "update_freq")

    def __init__(
        self,
        robot: Robot,
        chain: str = "chain",
        target: str | None = None,
        offset: Sequence[float] = (0.0, 0.0, 0.05),
        freq: float = HEAD_FOLLOW_HZ,
    ) -> None:
        super().__init__(robot, freq)
        self.chain_name = chain
        self.target = target
        self.offset = [float(v) for v in offset]
        self._last_goal: np.ndarray | None = None
        self._seed: dict[str, float] | None = None
        self._warned = False

    def _chain(self) -> RobotChain:
        chain = self.real_robot.extensions.get(self.chain_name)
        if not isinstance(chain, RobotChain):
            raise RuntimeError(f"the robot has no chain {self.chain_name!r} to move")
        return chain

    def followed(self) -> str | None:
        """The object followed now: ``target``, or the object added last (None without one)."""
        if self.target:
            return self.target
        simulation = self.real_robot.simulation
        links = self._chain().links
        objects = [n for n in simulation.body_names() if n not in links]
        return objects[-1] if objects else None

    def setup(self) -> None:
        if self.real_robot.simulation is None:
            raise RuntimeError("head_follow needs a robot simulated with MuJoCo (sim='mujoco')")
        self._chain()
        self.robot.compliant = False
        self._last_goal = None
        self._seed = None
        self._warned = False

    def update(self) -> None:
        chain = self._chain()
        name = self.followed()
        if name is None:
            if not self._warned:
                logger.warning("head_follow: no object in the scene to follow (add_object)")
                self._warned = True
            return
        where = self.real_robot.simulation.get_object_position(name, relative_to=chain.base)
        goal = np.asarray(where) + np.asarray(self.offset)
        if self._last_goal is not None and np.linalg.norm(goal - self._last_goal) < MOVED_M:
            return
        seed = self._seed or {m.name: m.present_position for m in chain.motors}
        angles, found = chain.model.closest(goal, None, seed)
        if self._last_goal is None and found.position_error_m > chain.model.options.tolerance_m:
            logger.info("head_follow: %s is out of reach; following as close as it can", name)
        self._last_goal = goal
        self._seed = {**seed, **angles}
        self.robot.goto_position(angles, 2.0 * self.period_s, control="minjerk")
