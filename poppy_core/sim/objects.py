"""Objects added to a simulation (cube, sphere, cylinder): their spec and the model rebuild."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import mujoco  # noqa: TID253 (this room is imported lazily, by the factory)

from poppy_core.errors import ConfigError

KINDS = ("cube", "sphere", "cylinder")
_COLORS = {"cube": [0.85, 0.2, 0.2, 1.0], "sphere": [0.2, 0.5, 0.85, 1.0],
           "cylinder": [0.2, 0.7, 0.3, 1.0]}  # fmt: skip


@dataclass(frozen=True)
class ObjectSpec:
    """A free object: kind, name, start position (m), size (half side or radius[, half height])."""

    kind: str
    name: str
    position: tuple[float, float, float]
    size: tuple[float, ...]
    mass_kg: float

    @classmethod
    def make(
        cls,
        kind: str,
        name: str,
        position: tuple[float, float, float],
        size: float | tuple[float, ...],
        mass: float,
    ) -> ObjectSpec:
        """Check and normalise the arguments of ``Simulation.add_object``.

        Raises:
            ConfigError: unknown kind, bad size or mass.
        """
        if kind not in KINDS:
            raise ConfigError(f"unknown object kind {kind!r} (one of {', '.join(KINDS)})",
                              field="kind", value=kind)  # fmt: skip
        sizes = (float(size),) if isinstance(size, (int, float)) else tuple(map(float, size))
        if not sizes or min(sizes) <= 0 or mass <= 0:
            raise ConfigError("object size and mass must be positive", field="size", value=size)
        x, y, z = position
        return cls(kind, name, (float(x), float(y), float(z)), sizes, float(mass))

    def geom_size(self) -> list[float]:
        """MuJoCo geom size: box half sides, sphere radius, cylinder radius and half height."""
        s = self.size
        if self.kind == "cube":
            return [s[0], s[0], s[0]] if len(s) == 1 else [s[0], s[1], s[2]]
        if self.kind == "sphere":
            return [s[0], 0.0, 0.0]
        return [s[0], s[1] if len(s) > 1 else s[0], 0.0]


_TYPES = {
    "cube": mujoco.mjtGeom.mjGEOM_BOX,
    "sphere": mujoco.mjtGeom.mjGEOM_SPHERE,
    "cylinder": mujoco.mjtGeom.mjGEOM_CYLINDER,
}


def add_objects(xml: str, specs: list[ObjectSpec]) -> Any:
    """Compile ``xml`` with ``specs`` added as free bodies (MjSpec); returns the MjModel."""
    spec = mujoco.MjSpec.from_string(xml)
    for obj in specs:
        body = spec.worldbody.add_body(name=obj.name, pos=list(obj.position))
        body.add_freejoint(name=f"{obj.name}_free")
        body.add_geom(
            name=obj.name,
            type=_TYPES[obj.kind],
            size=obj.geom_size(),
            mass=obj.mass_kg,
            rgba=_COLORS[obj.kind],
            contype=1,
            conaffinity=3,
        )
    return spec.compile()
