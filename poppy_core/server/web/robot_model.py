"""The robot's 3D model for the page's view, under ``/api/v1/model``: its URDF and meshes.

``GET /api/v1/model`` says how to draw the robot: where its URDF is, how each motor's angle
turns its URDF joint (``radians(scale * (degrees + offset_deg))``, as the chains read it), and
where each chain's tip is. ``GET /api/v1/model/robot.urdf`` is the profile's URDF as it is;
``GET /api/v1/model/meshes/NAME`` is ``profiles/<creature>/meshes/NAME``, the file a URDF's
``package://.../meshes/NAME`` names. Both are cached by the browser (an ETag, a max-age).
"""

from __future__ import annotations

import hashlib
import logging
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from fastapi import APIRouter, Request  # noqa: TID253 (the server room is FastAPI's)
from starlette.responses import FileResponse, Response

from poppy_core.errors import PoppyError
from poppy_core.robot import Robot
from poppy_core.server.deps import Service
from poppy_core.server.errors import ApiError
from poppy_core.server.schemas import Problem

logger = logging.getLogger(__name__)

router = APIRouter(prefix="/model", tags=["3D model"], responses={404: {"model": Problem}})

CACHE_S = 3600
"""How long the browser keeps the URDF and meshes before asking again (with their ETag)."""
MESH_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]{0,127}\.(stl|STL)")
MESH_TYPES = {".stl": "model/stl"}


@dataclass(frozen=True)
class ModelFiles:
    """Where a robot's URDF and meshes are, and the motors the model turns the other way."""

    urdf: Path
    meshes: Path
    reversed: tuple[str, ...]

    def joints(self, robot: Robot) -> dict[str, dict[str, float]]:
        """How each motor's angle turns its URDF joint: ``radians(scale * (deg + offset_deg))``
        (the motors' orientations and offsets as they are now: a calibration changes them)."""
        joints = {}
        for motor in robot.motors:
            sign = 1.0 if motor.direct else -1.0
            joints[motor.name] = {
                "scale": -sign if motor.name in self.reversed else sign,
                "offset_deg": float(motor.offset),
            }
        return joints


def model_files(robot: Robot) -> ModelFiles | None:
    """The robot's URDF (its kinematics section's model), or None when it has none."""
    from poppy_core.motion.chains import model_file

    config = robot.config
    if config is None:
        return None
    profile = config.profile
    kind = (profile.kind or profile.name) if profile is not None else None
    try:
        found = model_file(config, kind)
    except PoppyError as exc:
        logger.info("no 3D model for the page: %s", exc)
        return None
    if found is None or found[1].suffix.lower() != ".urdf":
        return None
    spec, path = found
    return ModelFiles(path, path.parent / "meshes", tuple(spec.reversed))


def _files(request: Request, service: Any) -> ModelFiles:
    state = request.app.state
    cached = getattr(state, "web_model", None)
    if cached is None:
        cached = model_files(service.robot) or False
        state.web_model = cached
    if not isinstance(cached, ModelFiles):
        raise ApiError(
            "not_found",
            "this robot has no 3D model: its config names no URDF",
            tip="add a kinematics section with a URDF model to the robot's config",
        )
    return cached


def chain_marks(robot: Robot) -> dict[str, dict[str, Any]]:
    """Each chain's base link, last joint and tip (in that joint's child frame), and target."""
    from poppy_core.motion.chains import robot_chains

    marks = {}
    for name, chain in robot_chains(robot).items():
        model = chain.model
        marks[name] = {
            "label": chain.label,
            "base": model.base,
            "tip_joint": model.names[-1],
            "tip": [float(v) for v in model.tip],
            "target": chain.target,
        }
    return marks


def _cached_file(request: Request, path: Path, media_type: str) -> Response:
    stat = path.stat()
    tag = hashlib.sha1(f"{path}:{stat.st_size}:{stat.st_mtime_ns}".encode()).hexdigest()[:20]
    etag = f'"{tag}"'
    headers = {"Cache-Control": f"max-age={CACHE_S}", "ETag": etag}
    if request.headers.get("if-none-match") == etag:
        return Response(status_code=304, headers=headers)
    return FileResponse(path, media_type=media_type, headers=headers)


@router.get("", summary="How to draw the robot: its URDF, its joints' frames, its chains")
async def model_route(request: Request, service: Service) -> dict[str, Any]:
    """The URDF's and meshes' addresses, each motor's joint mapping, the chains' tips."""
    files = _files(request, service)
    meshes = sorted(p.name for p in files.meshes.glob("*") if MESH_NAME.fullmatch(p.name))
    return {
        "urdf": "/api/v1/model/robot.urdf",
        "meshes": "/api/v1/model/meshes/",
        "mesh_files": meshes,
        "joints": files.joints(service.robot),
        "chains": chain_marks(service.robot),
    }


@router.get("/goals", summary="Where the gotos under way go: motors' goals, chains' targets")
async def goals_route(service: Service) -> dict[str, Any]:
    """``goals``: each motor moving under a goto -> its goal (degrees); ``targets``: each chain
    -> where its cartesian goto sends the tip (metres, in the chain's base frame) or null."""
    from poppy_core.motion.chains import robot_chains
    from poppy_core.robot.goto import running_goals

    robot = service.robot
    return {
        "goals": running_goals(robot.motors),
        "targets": {name: chain.target for name, chain in robot_chains(robot).items()},
    }


@router.get("/robot.urdf", summary="The robot's URDF", response_class=Response)
async def urdf_route(request: Request, service: Service) -> Response:
    """The profile's URDF file as it is (its meshes are under ``meshes/``)."""
    return _cached_file(request, _files(request, service).urdf, "application/xml")


@router.get("/meshes/{name}", summary="A mesh the URDF names", response_class=Response)
async def mesh_route(name: str, request: Request, service: Service) -> Response:
    """``profiles/<creature>/meshes/NAME`` (binary STL)."""
    files = _files(request, service)
    if not MESH_NAME.fullmatch(name):
        raise ApiError("not_found", f"no mesh {name!r}: a mesh is a file NAME.stl")
    path = files.meshes / name
    if not path.is_file():
        raise ApiError(
            "not_found",
            f"no mesh {name!r} in {files.meshes}",
            tip="the view draws the robot without it",
        )
    return _cached_file(request, path, MESH_TYPES[path.suffix.lower()])
