"""Objects added to a simulation (cube, sphere, cylinder, cone, card): their spec, the rebuild."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import mujoco  # noqa: TID253 (this room is imported lazily, by the factory)
import numpy as np

from poppy_core.errors import ConfigError

KINDS = ("cube", "sphere", "cylinder", "cone")
CONE_SIDES = 24  # a cone is a mesh (MuJoCo has no cone shape): a pyramid of this many sides
CARD_HALF_THICKNESS_M = 0.001
_COLORS = {
    "cube": [0.85, 0.2, 0.2, 1.0],
    "sphere": [0.2, 0.5, 0.85, 1.0],
    "card": [1.0] * 4,
    "cylinder": [0.2, 0.7, 0.3, 1.0],
    "cone": [0.9, 0.6, 0.1, 1.0],
}


@dataclass(frozen=True)
class ObjectSpec:
    """A free object: kind, name, start position (m), size (half side or radius[, half height])."""

    kind: str
    name: str
    position: tuple[float, float, float]
    size: tuple[float, ...]
    mass_kg: float
    quat: tuple[float, float, float, float] = (1.0, 0.0, 0.0, 0.0)
    fixed: bool = False
    """Held where it was put (no free joint): a card in mid-air stays there."""
    texture: np.ndarray | None = field(default=None, compare=False, repr=False)
    """RGB image on the card's front face (local -y), as seen from the front."""

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
            raise ConfigError(
                f"unknown object kind {kind!r} (one of {', '.join(KINDS)})",
                field="kind",
                value=kind,
            )
        sizes = (float(size),) if isinstance(size, (int, float)) else tuple(map(float, size))
        if not sizes or min(sizes) <= 0 or mass <= 0:
            raise ConfigError("object size and mass must be positive", field="size", value=size)
        x, y, z = position
        return cls(kind, name, (float(x), float(y), float(z)), sizes, float(mass))

    @classmethod
    def card(
        cls,
        name: str,
        pixels: np.ndarray,
        position: tuple[float, float, float],
        side: float,
        facing: tuple[float, float, float],
    ) -> ObjectSpec:
        """A square card of side ``side`` (m) showing ``pixels`` (``picture_pixels``), held at
        ``position`` with its front looking along ``facing``.

        Raises:
            ConfigError: no direction to face.
        """
        return cls(
            "card",
            name,
            tuple(float(v) for v in position),  # type: ignore[arg-type]
            (side / 2,),
            0.01,
            facing_quat(facing),
            True,
            pixels,
        )

    def geom_size(self) -> list[float]:
        """MuJoCo geom size: box half sides, sphere radius, cylinder radius and half height."""
        s = self.size
        if self.kind == "card":
            return [s[0], CARD_HALF_THICKNESS_M, s[0]]
        if self.kind == "cube":
            return [s[0], s[0], s[0]] if len(s) == 1 else [s[0], s[1], s[2]]
        if self.kind == "sphere":
            return [s[0], 0.0, 0.0]
        return [s[0], s[1] if len(s) > 1 else s[0], 0.0]

    def cone_vertices(self) -> list[float]:
        """A cone's mesh (radius ``size[0]``, half height ``size[1]``, centred, tip up): its
        base circle's points and its tip, flattened."""
        radius = self.size[0]
        half = self.size[1] if len(self.size) > 1 else radius
        points: list[float] = []
        for k in range(CONE_SIDES):
            angle = 2 * np.pi * k / CONE_SIDES
            points += [radius * float(np.cos(angle)), radius * float(np.sin(angle)), -half]
        return [*points, 0.0, 0.0, half]


_TYPES = {
    "card": mujoco.mjtGeom.mjGEOM_BOX,
    "cube": mujoco.mjtGeom.mjGEOM_BOX,
    "sphere": mujoco.mjtGeom.mjGEOM_SPHERE,
    "cylinder": mujoco.mjtGeom.mjGEOM_CYLINDER,
    "cone": mujoco.mjtGeom.mjGEOM_MESH,
}


VISUAL_CLASS = "visual"  # the models' geoms that are drawn, never simulated (mjcf.py)


def add_objects(
    xml: str,
    specs: list[ObjectSpec],
    assets: dict[str, bytes] | None = None,
    *,
    drawn: bool = True,
) -> Any:
    """Compile ``xml`` (its mesh files in ``assets``) with ``specs`` added as free bodies
    (MjSpec); returns the MjModel. ``drawn=False``: without the geoms of class ``visual``
    (the meshes), the model the physics steps: the same bodies, joints and cameras."""
    spec = mujoco.MjSpec.from_string(xml, assets=assets or {})
    if not drawn:
        for geom in list(spec.geoms):
            if geom.classname.name == VISUAL_CLASS:
                spec.delete(geom)
    for obj in specs:
        body = spec.worldbody.add_body(name=obj.name, pos=list(obj.position), quat=list(obj.quat))
        if not obj.fixed:
            body.add_freejoint(name=f"{obj.name}_free")
        geom = body.add_geom(
            name=obj.name,
            type=_TYPES[obj.kind],
            size=obj.geom_size(),
            mass=obj.mass_kg,
            rgba=_COLORS[obj.kind],
            contype=1,
            conaffinity=3,
        )
        if obj.kind == "cone":
            spec.add_mesh(name=f"{obj.name}_cone", uservert=obj.cone_vertices())
            geom.meshname = f"{obj.name}_cone"
        if obj.texture is not None:
            geom.material = _textured(spec, obj.name, obj.texture)
            geom.rgba = [1.0, 1.0, 1.0, 1.0]
    return spec.compile()


def _textured(spec: Any, name: str, image: np.ndarray) -> str:
    """A material showing ``image`` (RGB) on a box's -y face, as seen from the front."""
    pixels = np.ascontiguousarray(image[:, :, :3], dtype=np.uint8)
    height, width = pixels.shape[:2]
    texture = spec.add_texture(
        name=f"{name}_texture",
        type=mujoco.mjtTexture.mjTEXTURE_2D,
        width=width,
        height=height,
        nchannel=3,
    )
    texture.data = pixels.tobytes()
    material = spec.add_material(name=f"{name}_material")
    roles = list(material.textures)
    roles[int(mujoco.mjtTextureRole.mjTEXROLE_RGB)] = f"{name}_texture"
    material.textures = roles
    return f"{name}_material"


def facing_quat(facing: tuple[float, float, float]) -> tuple[float, float, float, float]:
    """Orientation of a card whose front (local -y) looks along ``facing``, its top up."""
    front = np.asarray(facing, dtype=float)
    norm = float(np.linalg.norm(front))
    if norm == 0:
        raise ConfigError("a card must face some direction", field="facing", value=facing)
    y = -front / norm
    up = np.array([0.0, 0.0, 1.0]) if abs(y[2]) < 0.95 else np.array([1.0, 0.0, 0.0])
    z = up - y * float(up @ y)
    z /= float(np.linalg.norm(z))
    x = np.cross(y, z)
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, np.column_stack([x, y, z]).ravel())
    w, qx, qy, qz = (float(v) for v in quat)
    return (w, qx, qy, qz)


def picture_pixels(image: object) -> np.ndarray:
    """``image`` as the pixels a card shows.

    Raises:
        ConfigError: not an (height, width, 3) uint8 RGB image.
    """
    pixels = np.asarray(image)
    if pixels.ndim != 3 or pixels.shape[2] < 3 or pixels.dtype != np.uint8:
        raise ConfigError(
            "a picture is an (height, width, 3) uint8 RGB image",
            field="image",
            value=getattr(pixels, "shape", None),
        )
    return pixels


def marker_picture(
    marker_id: int, size: float, family: str, dictionary: str
) -> tuple[np.ndarray, float]:
    """The RGB picture of a marker's card and the card's side (m): the marker's black square
    is ``size`` (m) wide, with a white margin of one cell around it.

    Raises:
        SensorError: unknown family, dictionary or id.
    """
    from poppy_core.sensors.markers import marker_image

    grey = np.asarray(marker_image(marker_id, family, dictionary, size_px=240))
    image = np.repeat(grey[:, :, None], 3, axis=2)
    dark = np.nonzero(grey.min(axis=0) < 128)[0]  # columns of the black square
    card_half = size / 2 * grey.shape[1] / float(dark[-1] - dark[0] + 1)
    return image, 2 * card_half
