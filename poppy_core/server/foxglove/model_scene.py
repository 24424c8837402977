"""The robot's meshes as one Foxglove scene, for files (``poppy record --mcap``).

Foxglove opening a file has no server to fetch the URDF's ``package://`` meshes from; the
``/robot_model`` scene carries them inside: one entity per URDF link with a mesh visual, in
that link's frame (``/tf`` moves it), each mesh embedded as ``model/stl`` with the visual's
origin, scale and colour.
"""

from __future__ import annotations

import logging
import xml.etree.ElementTree as ElementTree
from typing import TYPE_CHECKING

from foxglove.messages import (
    Color,
    ModelPrimitive,
    Pose,
    Quaternion,
    SceneEntity,
    SceneUpdate,
    Timestamp,
    Vector3,
)

from poppy_core.kinematics.transforms import rpy_matrix
from poppy_core.server.ros2.joints import matrix_quaternion

if TYPE_CHECKING:
    from poppy_core.server.foxglove.assets import RobotAssets

logger = logging.getLogger(__name__)

MEDIA_TYPES = {".stl": "model/stl", ".dae": "model/vnd.collada+xml"}


def _numbers(text: str | None, default: tuple[float, ...]) -> tuple[float, ...]:
    if not text:
        return default
    try:
        values = tuple(float(v) for v in text.split())
    except ValueError:
        return default
    return values if len(values) == len(default) else default


def model_scene(urdf: str, assets: RobotAssets, now: float) -> SceneUpdate:
    """Every link's mesh visuals, embedded; a mesh that cannot be read is left out (logged)."""
    root = ElementTree.fromstring(urdf)
    entities = []
    for link in root.iter("link"):
        name = link.get("name", "")
        models = []
        for visual in link.iter("visual"):
            mesh = visual.find("geometry/mesh")
            if mesh is None:
                continue
            uri = mesh.get("filename", "")
            data = assets.fetch(uri)
            suffix = uri[uri.rfind(".") :].lower()
            if data is None or suffix not in MEDIA_TYPES:
                logger.info("the robot's scene: no mesh %r for link %s", uri[:200], name)
                continue
            origin = visual.find("origin")
            xyz = _numbers(origin.get("xyz") if origin is not None else None, (0.0, 0.0, 0.0))
            rpy = _numbers(origin.get("rpy") if origin is not None else None, (0.0, 0.0, 0.0))
            scale = _numbers(mesh.get("scale"), (1.0, 1.0, 1.0))
            x, y, z, w = matrix_quaternion(rpy_matrix(*rpy))
            rgba = visual.find("material/color")
            colour = _numbers(rgba.get("rgba") if rgba is not None else None, (0.6, 0.6, 0.6, 1.0))
            models.append(
                ModelPrimitive(
                    pose=Pose(
                        position=Vector3(x=xyz[0], y=xyz[1], z=xyz[2]),
                        orientation=Quaternion(x=x, y=y, z=z, w=w),
                    ),
                    scale=Vector3(x=scale[0], y=scale[1], z=scale[2]),
                    color=Color(r=colour[0], g=colour[1], b=colour[2], a=colour[3]),
                    override_color=rgba is not None,
                    media_type=MEDIA_TYPES[suffix],
                    data=data,
                )
            )
        if models:
            entities.append(
                SceneEntity(
                    timestamp=Timestamp.from_epoch_secs(now),
                    frame_id=name,
                    id=f"robot/{name}",
                    frame_locked=True,
                    models=models,
                )
            )
    return SceneUpdate(entities=entities)
