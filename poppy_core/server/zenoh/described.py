"""What a robot's ``poppy/NAME/description`` says of its creature and motors (JSON-ready)."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

from poppy_core.server.web.about_parts import camera_views

if TYPE_CHECKING:
    from poppy_core.robot import Robot


def creature(robot: Robot) -> str:
    """The profile's name (empty for a robot built without a profile)."""
    profile = robot.config.profile if robot.config is not None else None
    return profile.name if profile is not None else ""


def motors(robot: Robot) -> list[dict[str, Any]]:
    """Each motor's name, id, model and angle limits (None for a limit not read)."""
    return [
        {
            "name": m.name,
            "id": m.id,
            "model": m.model.name,
            "angle_limit": _jsonable(getattr(m, "angle_limit", None)),
        }
        for m in robot.motors
    ]


def cameras(robot: Robot) -> dict[str, Any]:
    """The cameras with a picture (name and label, as the robot's page shows them) and what a
    viewer says without one (an ideal simulation's black frames are no picture)."""
    views, no_camera = camera_views(robot)
    return {"cameras": views, "no_camera": no_camera}


def _jsonable(value: Any) -> Any:
    if isinstance(value, tuple | list):
        return [_jsonable(v) for v in value]
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value
