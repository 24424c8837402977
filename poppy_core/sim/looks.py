"""How each robot looks in its MuJoCo model: colours, collision shapes, stand, cameras."""

from __future__ import annotations

from dataclasses import dataclass

from poppy_core.sim.framing import View
from poppy_core.sim.urdf import Vec3


@dataclass(frozen=True)
class Style:
    """How a robot looks and where it stands."""

    radius_m: float  # of the collision capsules
    rgba: str  # of the shapes drawn where a link has no mesh
    mount: str  # "table", "support" or "floor"
    views: tuple[View, ...]  # the model's cameras: direction from the robot (distance computed)
    mesh_rgba: str  # of the visual meshes


# The robots face -y (the Humanoid's and Torso's eyes, the Ergo Jr's arm at its zero pose):
# `front` sees them from the front right, `side` from their left, `top` from above (the image's
# top towards their back).
def _views(front_rise: float, side_rise: float) -> tuple[View, ...]:
    return (
        View("front", (1.0, -1.0, front_rise)),
        View("side", (1.0, 0.0, side_rise)),
        View("top", (0.0, -0.25, 1.0)),
    )


STYLES: dict[str, Style] = {
    "ergo-jr": Style(0.012, "0.95 0.95 0.95 1", "table", _views(0.45, 0.35), "0.93 0.93 0.95 1"),
    "torso": Style(0.022, "0.92 0.92 0.9 1", "support", _views(0.3, 0.15), "0.9 0.9 0.88 1"),
    "humanoid": Style(0.025, "0.92 0.92 0.9 1", "floor", _views(0.25, 0.1), "0.9 0.9 0.88 1"),
}
# link -> (geom type, size) drawn at the link's centre of mass, so the robot looks like itself.
BLOBS: dict[str, dict[str, tuple[str, Vec3]]] = {
    "ergo-jr": {"tip": ("sphere", (0.018, 0.0, 0.0))},
    "torso": {"head": ("sphere", (0.055, 0.0, 0.0)), "chest": ("box", (0.07, 0.05, 0.04))},
    "humanoid": {
        "head": ("sphere", (0.055, 0.0, 0.0)),
        "chest": ("box", (0.07, 0.05, 0.04)),
        "pelvis": ("box", (0.06, 0.035, 0.03)),
    },
}


@dataclass(frozen=True)
class CameraMount:
    """Where the robot's own camera sits: in ``body``, ``ahead_m`` in front of its centre of mass
    (out of the head's shape), looking along ``look`` with ``up`` up (world axes at the zero
    pose), with a vertical field of view of ``fovy_deg``."""

    body: str
    ahead_m: float
    look: Vec3
    up: Vec3
    fovy_deg: float


# The MuJoCo camera `camera` (the name of the camera sensor in pypot's configs) sits where the
# real one does. Ergo Jr: the Raspberry Pi camera in its head (the tip), looking out along the
# end effector (-z of the tip frame, as pypot's IK tip [0, 0, -0.07]); field of view 41.4°
# vertical (Raspberry Pi camera module v1, OV5647: 53.5° × 41.4°). Torso/Humanoid: the camera
# in the head's face, looking forward (-y); the Poppy BOM names a 120° camera: 105° vertical at
# 4:3 for a pinhole of 120° horizontal.
CAMERAS: dict[str, CameraMount] = {
    "ergo-jr": CameraMount("tip", 0.02, (0.0, -1.0, 0.0), (0.0, 0.0, 1.0), 41.4),
    "torso": CameraMount("head", 0.06, (0.0, -1.0, 0.0), (0.0, 0.0, 1.0), 105.0),
    "humanoid": CameraMount("head", 0.06, (0.0, -1.0, 0.0), (0.0, 0.0, 1.0), 105.0),
}
CAMERA_NAME = "camera"
TABLE_TOP_M = 0.05
SUPPORT_TOP_M = 0.75
