"""pypot's V-REP calls over the MuJoCo world: the robot's ``reset_simulation``, objects' poses,
shapes added, the simulated time, a scene file, tracked objects and collisions.

pypot's ``from_vrep`` robot had ``reset_simulation``, ``get_object_position``,
``get_object_orientation`` and ``current_simulation_time``; its ``VrepIO`` (reference lines
7061-7283) ``set_object_position``, ``add_cube``/``add_sphere``/``add_cylinder``/``add_cone``,
``get_simulation_current_time``, ``get_collision_state`` and ``load_scene``; ``tracked_objects``
and ``tracked_collisions`` became ``robot.<name>`` with ``position``/``orientation`` and
``colliding``. Here they are the robot's methods and reach ``robot.simulation``
(``sim="mujoco"``). V-REP's scenes named a link's shape ``<link>_visual``: that name reads as
the link's body. Orientations are V-REP's Euler angles (rad): the turn
``Rx(alpha) @ Ry(beta) @ Rz(gamma)`` (CoppeliaSim's "Euler angles" convention); sizes are
V-REP's full extents (m): a cube's sides, a sphere's diameter, a cylinder's or cone's diameter
and height.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, Protocol

from poppy_core.checks import positive
from poppy_core.errors import ConfigError

VREP_VISUAL_SUFFIX = "_visual"
Quat = tuple[float, float, float, float]


class VrepHost(Protocol):
    """What ``VrepNames`` needs of the robot it is mixed into (``Robot`` gives it)."""

    @property
    def simulation(self) -> Any:
        """The MuJoCo world (``poppy_core.sim.world.Simulation``), or None for a real robot."""
        ...

    def attach(self, name: str, obj: object) -> None:
        """Make ``obj`` reachable as ``robot.<name>``."""
        ...


class VrepNames:
    """The V-REP robot's methods, for a ``VrepHost`` (a ``Robot``) whose ``simulation`` is a
    MuJoCo world."""

    def reset_simulation(self: VrepHost) -> None:
        """pypot's name for ``robot.simulation.reset()``: the world back to its start pose."""
        _world(self, "reset_simulation").reset()

    def get_object_position(
        self: VrepHost,
        name: str,
        relative_to: str | None = None,
        relative_to_object: str | None = None,
    ) -> list[float]:
        """Body ``name``'s position (m) in the world, or in body ``relative_to``'s frame
        (pypot's keyword ``relative_to_object`` too; ``l_forearm_visual`` reads as
        ``l_forearm``)."""
        simulation = _world(self, "get_object_position")
        frame = relative_to if relative_to is not None else relative_to_object
        body = _body_name(simulation, name)
        base = None if frame is None else _body_name(simulation, frame)
        position: list[float] = simulation.get_object_position(body, base)
        return position

    def get_object_orientation(
        self: VrepHost,
        name: str,
        relative_to: str | None = None,
        relative_to_object: str | None = None,
    ) -> list[float]:
        """Body ``name``'s orientation as V-REP's Euler angles (rad), in the world or in body
        ``relative_to``'s frame."""
        simulation = _world(self, "get_object_orientation")
        frame = relative_to if relative_to is not None else relative_to_object
        base = None if frame is None else _body_name(simulation, frame)
        w, x, y, z = simulation.get_object_orientation(_body_name(simulation, name), base)
        return euler_from_quat((w, x, y, z))

    def set_object_position(self: VrepHost, name: str, position: Any = (0.0, 0.0, 0.0)) -> None:
        """Put object ``name`` at ``position`` (m, world frame), at rest."""
        simulation = _world(self, "set_object_position")
        simulation.set_object_position(_body_name(simulation, name), position)

    def set_object_orientation(self: VrepHost, name: str, orientation: Any) -> None:
        """Turn object ``name`` to V-REP's Euler angles ``orientation`` (rad, world frame)."""
        simulation = _world(self, "set_object_orientation")
        angles = [float(a) for a in _three(orientation, "orientation")]
        simulation.set_object_orientation(_body_name(simulation, name), quat_from_euler(angles))

    def get_simulation_current_time(self: VrepHost, timer: str = "CurrentTime") -> float:
        """The simulated time (s) since the world was built (``timer``: V-REP's signal name,
        unused)."""
        return float(_world(self, "get_simulation_current_time").time)

    @property
    def current_simulation_time(self: VrepHost) -> float:
        """pypot's ``robot.current_simulation_time``: the simulated time (s)."""
        return float(_world(self, "current_simulation_time").time)

    def add_cube(self: VrepHost, name: str, position: Any, sizes: Any, mass: float) -> None:
        """A free box of sides ``sizes`` (x, y, z; m) and ``mass`` (kg) at ``position``."""
        x, y, z = (positive(s, "sizes") / 2 for s in _three(sizes, "sizes"))
        _add(self, "add_cube", "cube", name, position, (x, y, z), mass)

    def add_sphere(
        self: VrepHost, name: str, position: Any, sizes: Any, mass: float, precision: Any = (10, 10)
    ) -> None:
        """A free ball of diameter ``sizes[0]`` (m) and ``mass`` (kg) (``precision``: V-REP's
        faceting, unused: MuJoCo's ball is round)."""
        radius = positive(_three(sizes, "sizes")[0], "sizes") / 2
        _add(self, "add_sphere", "sphere", name, position, (radius,), mass)

    def add_cylinder(
        self: VrepHost, name: str, position: Any, sizes: Any, mass: float, precision: Any = (10, 10)
    ) -> None:
        """A free upright cylinder of diameter ``sizes[0]`` and height ``sizes[2]`` (m)."""
        _add(self, "add_cylinder", "cylinder", name, position, _upright(sizes), mass)

    def add_cone(
        self: VrepHost, name: str, position: Any, sizes: Any, mass: float, precision: Any = (10, 10)
    ) -> None:
        """A free upright cone (tip up) of base diameter ``sizes[0]`` and height ``sizes[2]``."""
        _add(self, "add_cone", "cone", name, position, _upright(sizes), mass)

    def get_collision_state(self: VrepHost, collision_name: str) -> bool:
        """Whether body ``collision_name`` touches another body or the world now."""
        simulation = _world(self, "get_collision_state")
        return bool(simulation.colliding(_body_name(simulation, collision_name)))

    def load_scene(self: VrepHost, scene_path: str | Path, start: bool = False) -> None:
        """Replace the world by the MJCF scene at ``scene_path`` (the robot and its props; see
        ``Simulation.load_scene``); ``start``: V-REP's, the physics already runs."""
        _world(self, "load_scene").load_scene(scene_path)

    def track_objects(self: VrepHost, names: Any) -> None:
        """pypot's ``tracked_objects``: ``robot.<name>.position`` and ``.orientation`` of each
        body (and ``.colliding``)."""
        simulation = _world(self, "track_objects")
        for name in _names(names):
            simulation.get_object_position(_body_name(simulation, name))  # known, or an error
            self.attach(name, WorldObject(simulation, _body_name(simulation, name)))

    def track_collisions(self: VrepHost, names: Any) -> None:
        """pypot's ``tracked_collisions``: ``robot.<name>.colliding`` of each body (a body
        both tracked and a collision is one ``robot.<name>``)."""
        simulation = _world(self, "track_collisions")
        for name in _names(names):
            simulation.get_object_position(_body_name(simulation, name))
            self.attach(name, WorldObject(simulation, _body_name(simulation, name)))


def _add(
    host: VrepHost, call: str, kind: str, name: str, position: Any, size: Any, mass: float
) -> None:
    simulation = _world(host, call)
    place = tuple(float(v) for v in _three(position, "position"))
    simulation.add_object(kind, name, place, size=size, mass=positive(mass, "mass"))


def _world(host: VrepHost, call: str) -> Any:
    """``host``'s MuJoCo world, for pypot's call ``call``.

    Raises:
        ConfigError: a real robot (no simulation).
    """
    if host.simulation is None:
        raise ConfigError(
            f"{call}() needs a simulated robot: build it with simulator='mujoco' "
            "(PoppyHumanoid(simulator='mujoco'), from_profile(..., sim='mujoco'))",
            field=call,
        )
    return host.simulation


class WorldObject:
    """A tracked object or collision (pypot's ``ObjectTracker``, ``VrepCollisionDetector``):
    its pose and contacts, read when asked."""

    def __init__(self, simulation: Any, name: str) -> None:
        self._simulation = simulation
        self.name = name

    @property
    def position(self) -> list[float]:
        """World position (m)."""
        position: list[float] = self._simulation.get_object_position(self.name)
        return position

    @property
    def orientation(self) -> list[float]:
        """V-REP's Euler angles (rad), world frame."""
        w, x, y, z = self._simulation.get_object_orientation(self.name)
        return euler_from_quat((w, x, y, z))

    @property
    def colliding(self) -> bool:
        """Whether the body touches another body or the world now."""
        return bool(self._simulation.colliding(self.name))


def _body_name(simulation: Any, name: str) -> str:
    if name.endswith(VREP_VISUAL_SUFFIX) and name not in simulation.body_names():
        return name[: -len(VREP_VISUAL_SUFFIX)]
    return name


def _names(names: Any) -> list[str]:
    return [names] if isinstance(names, str) else [str(n) for n in names]


def _three(values: Any, field: str) -> list[Any]:
    try:
        items = list(values)
    except TypeError:
        items = []
    if len(items) != 3:
        raise ConfigError(f"{field} must be 3 numbers, not {values!r}", field=field)
    return items


def _upright(sizes: Any) -> tuple[float, float]:
    """(radius, half height) of an upright solid of V-REP's ``sizes`` (diameter, _, height)."""
    sides = _three(sizes, "sizes")
    return (positive(sides[0], "sizes") / 2, positive(sides[2], "sizes") / 2)


def quat_from_euler(angles: list[float]) -> Quat:
    """V-REP's Euler angles (alpha, beta, gamma: ``Rx @ Ry @ Rz``) as a quaternion (w, x, y, z)."""
    a, b, c = (x / 2 for x in angles)
    qx = (math.cos(a), math.sin(a), 0.0, 0.0)
    qy = (math.cos(b), 0.0, math.sin(b), 0.0)
    qz = (math.cos(c), 0.0, 0.0, math.sin(c))
    from poppy_core.kinematics.transforms import quat_mul  # numpy: only when a sim call asks

    return quat_mul(quat_mul(qx, qy), qz)


def euler_from_quat(q: Quat) -> list[float]:
    """The quaternion ``q`` (w, x, y, z) as V-REP's Euler angles (rad)."""
    w, x, y, z = q
    r01 = 2 * (x * y - w * z)
    r00 = 1 - 2 * (y * y + z * z)
    r02 = 2 * (x * z + w * y)
    r12 = 2 * (y * z - w * x)
    r22 = 1 - 2 * (x * x + y * y)
    beta = math.asin(max(-1.0, min(1.0, r02)))
    return [math.atan2(-r12, r22), beta, math.atan2(-r01, r00)]
