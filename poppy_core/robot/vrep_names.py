"""pypot's V-REP robot names over the MuJoCo world: ``reset_simulation``, ``get_object_position``.

pypot's ``from_vrep`` gave its robot these two; the documentation's simulation examples call
them (``poppy.reset_simulation()``, ``poppy.get_object_position('l_forearm_visual')``). Here they
reach ``robot.simulation`` (``sim="mujoco"``). V-REP's scenes named a link's shape
``<link>_visual``; that name reads as the link's body.
"""

from __future__ import annotations

from typing import Any

from poppy_core.errors import ConfigError

VREP_VISUAL_SUFFIX = "_visual"


class VrepNames:
    """The V-REP robot's methods, for a ``Robot`` whose ``simulation`` is a MuJoCo world."""

    simulation: Any

    def reset_simulation(self) -> None:
        """pypot's name for ``robot.simulation.reset()``: the world back to its start pose."""
        self._simulation("reset_simulation").reset()

    def get_object_position(self, name: str, relative_to: str | None = None) -> list[float]:
        """pypot's name for ``robot.simulation.get_object_position``: body ``name``'s position
        (m) in the world, or in body ``relative_to``'s frame (``l_forearm_visual`` is read as
        ``l_forearm``)."""
        simulation = self._simulation("get_object_position")
        body = _body_name(simulation, name)
        frame = None if relative_to is None else _body_name(simulation, relative_to)
        position: list[float] = simulation.get_object_position(body, frame)
        return position

    def _simulation(self, call: str) -> Any:
        if self.simulation is None:
            raise ConfigError(
                f"{call}() needs a simulated robot: build it with simulator='mujoco' "
                "(PoppyHumanoid(simulator='mujoco'), from_profile(..., sim='mujoco'))",
                field=call,
            )
        return self.simulation


def _body_name(simulation: Any, name: str) -> str:
    if name.endswith(VREP_VISUAL_SUFFIX) and name not in simulation.body_names():
        return name[: -len(VREP_VISUAL_SUFFIX)]
    return name
