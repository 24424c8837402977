"""What a robot's ``poppy/NAME/description`` says of its creature and motors (JSON-ready)."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

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


def _jsonable(value: Any) -> Any:
    if isinstance(value, tuple | list):
        return [_jsonable(v) for v in value]
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value
