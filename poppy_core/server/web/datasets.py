"""The page's dataset viewer's routes under ``/api/v1/datasets``: the LeRobot datasets of the
robot's data folder (LeRobot's home, ``$HF_LEROBOT_HOME``) and any added by name
(``poppy dataset view``), an episode's frames, and its cameras' video files (HTTP Range, so the
browser can seek). Read only: nothing here moves the robot.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

from fastapi import APIRouter, Request  # noqa: TID253 (the server room is FastAPI's)
from fastapi import Path as PathParam  # noqa: TID253
from starlette.responses import FileResponse, JSONResponse, Response

from poppy_core.server.errors import ApiError
from poppy_core.server.schemas import Problem

if TYPE_CHECKING:
    from fastapi import FastAPI

router = APIRouter(
    prefix="/datasets",
    tags=["datasets"],
    responses={404: {"model": Problem}, 422: {"model": Problem}},
)

EPISODE = PathParam(..., ge=0, le=10_000_000, description="The episode's number (from 0).")


def add_dataset(app: FastAPI, repo_id: str, root: Path) -> None:
    """List the dataset in ``root`` as ``repo_id`` on the page (besides the data folder's)."""
    extra: dict[str, Path] = getattr(app.state, "datasets_extra", {})
    extra[repo_id] = Path(root).expanduser()
    app.state.datasets_extra = extra


def _home() -> Path:
    from poppy_core.dataset.layout import lerobot_home

    return lerobot_home()


def _datasets(request: Request) -> dict[str, Path]:
    from poppy_core.extras import require

    require("pyarrow", extra="dataset")
    from poppy_core.dataset.shelf import find_datasets

    return find_datasets(_home(), dict(getattr(request.app.state, "datasets_extra", {})))


def _folder(request: Request, user: str, name: str) -> Path:
    from poppy_core.dataset.shelf import lookup

    return lookup(_datasets(request), f"{user}/{name}")


@router.get("", summary="The datasets the page can play: their episodes, tasks and cameras")
def datasets_route(request: Request) -> dict[str, Any]:
    """``home``: the data folder read; ``datasets``: each with its episodes (index, frames,
    duration_s, tasks), fps, cameras and joints (or ``error`` when it cannot be read)."""
    from poppy_core.dataset.shelf import describe

    found = _datasets(request)
    return {
        "home": str(_home()),
        "datasets": [describe(repo_id, root) for repo_id, root in found.items()],
    }


@router.get(
    "/{user}/{name}/episodes/{episode}",
    summary="An episode's frames for the player",
    response_class=JSONResponse,
)
def episode_route(request: Request, user: str, name: str, episode: int = EPISODE) -> JSONResponse:
    """timestamps (s), state and action per frame (degrees, in ``motors`` order), the task,
    and each camera's span in its video file (``from_s``/``to_s``, meta/episodes')."""
    from poppy_core.dataset.shelf import episode_frames

    root = _folder(request, user, name)
    answer = episode_frames(root, episode)
    answer["repo_id"] = f"{user}/{name}"
    for video in answer["videos"]:
        video["url"] = f"/api/v1/datasets/{user}/{name}/episodes/{episode}/video/{video['camera']}"
    return JSONResponse(answer)  # plain lists of numbers: no encoder pass over every value


@router.get(
    "/{user}/{name}/episodes/{episode}/video/{camera}",
    summary="The mp4 file holding a camera's frames of an episode (Range requests answered)",
    response_class=Response,
)
def video_route(
    request: Request, user: str, name: str, camera: str, episode: int = EPISODE
) -> Response:
    """The whole file, which may hold other episodes too: the episode's span in it is the
    episode route's ``from_s``/``to_s``."""
    from poppy_core.dataset.shelf import video_file

    path = video_file(_folder(request, user, name), episode, camera)
    if not path.is_file():
        raise ApiError("not_found", f"{camera}'s video file of episode {episode} is missing")
    return FileResponse(path, media_type="video/mp4", headers={"Cache-Control": "no-cache"})
