"""v1: a LeRobot dataset recorded on the served robot (``recordings.DatasetRecordings``): start
it, read its live state, and lerobot-record's three keys (end the episode, record it again,
stop)."""

from typing import Any

from fastapi import APIRouter, Request  # noqa: TID253 (the server room is FastAPI's)
from pydantic import BaseModel, Field
from starlette.concurrency import run_in_threadpool

from poppy_core.motion.recording_session import ESC, LEFT, RIGHT
from poppy_core.server.deps import Service
from poppy_core.server.recordings import DatasetRequest
from poppy_core.server.routers.common import client_of
from poppy_core.server.schemas import Problem

router = APIRouter(
    tags=["recording"],
    responses={409: {"model": Problem}, 422: {"model": Problem}, 503: {"model": Problem}},
)


class RecordingBody(BaseModel):
    """What to record. Numbers are checked as ``poppy dataset record`` checks its options (a
    refusal is a 422 in one line)."""

    repo_id: str = Field(description="The dataset's name, user/name (its folder: LeRobot's).")
    task: str = Field(description="What is done, in words (one line).")
    source: str = Field(
        description="The actions: by_hand (the robot compliant, moved by hand), move (a "
        "library move played each episode) or primitive."
    )
    move: str | None = Field(None, description="The move, with source move.")
    primitive: str | None = Field(None, description="The primitive, with source primitive.")
    episodes: int | float = Field(1, description="Episodes to record (1 to 10000).")
    episode_s: float = Field(20.0, description="Length of an episode in s (0.1 to 3600).")
    reset_s: float = Field(5.0, description="Pause between episodes in s (0 to 3600).")
    fps: int | float = Field(30, description="Frames per second (1 to 240).")
    cameras: list[str] | None = Field(
        None, description="Cameras of the robot to record; null: every one, []: none."
    )
    resume: bool = Field(False, description="Add episodes to the dataset of this repo_id.")


class RecordingState(BaseModel):
    """The recording under way, or the last one (``phase`` idle when there was none)."""

    active: bool
    phase: str = Field(
        description="idle, starting, recording, resetting, finishing (the dataset being written)"
        " or done."
    )
    repo_id: str | None = None
    folder: str | None = Field(None, description="The dataset's folder on the robot.")
    task: str | None = None
    source: str | None = None
    cameras: list[str] | None = None
    episode: int | None = Field(None, description="The episode under way, from 1.")
    episodes: int | None = None
    elapsed_s: float | None = Field(None, description="Time in the episode (or the reset).")
    duration_s: float | None = Field(None, description="Length of the episode (or reset).")
    frames: int | None = Field(None, description="Frames of the episode under way.")
    dropped: int | None = Field(None, description="Frames dropped in the episode under way.")
    dropped_total: int | None = Field(None, description="Dropped in the saved episodes.")
    rerecorded: int | None = Field(None, description="Episodes dropped and recorded again.")
    saved: list[dict[str, Any]] | None = Field(None, description="The episodes saved.")
    total_episodes: int | None = Field(None, description="Episodes the dataset holds.")
    error: str | None = Field(None, description="Why the recording stopped, if it failed.")


@router.get("/recording", summary="The dataset recording under way (or the last one)")
async def recording_state(service: Service) -> RecordingState:
    """Episode i/N, phase, time, frames, dropped frames, the dataset's folder."""
    return RecordingState(**service.recordings.state())


@router.post("/recording", summary="Record a LeRobot dataset (one recording at a time)")
async def start_recording(
    body: RecordingBody, service: Service, request: Request
) -> RecordingState:
    """Starts recording ``episodes`` episodes into LeRobot's folder for ``repo_id``; a
    recording under way is a 409; a bad input a 422."""
    asked = DatasetRequest(**body.model_dump())
    state = await run_in_threadpool(service.recordings.start, asked, client_of(request))
    return RecordingState(**state)


@router.post("/recording/end-episode", summary="End the episode (saved) or the reset: →")
async def end_episode(service: Service) -> RecordingState:
    """As the right arrow of ``poppy dataset record``."""
    return RecordingState(**service.recordings.press(RIGHT))


@router.post("/recording/rerecord", summary="Drop the episode and record it again: ←")
async def rerecord(service: Service) -> RecordingState:
    """As the left arrow of ``poppy dataset record``: its frames are not saved."""
    return RecordingState(**service.recordings.press(LEFT))


@router.post("/recording/stop", summary="Stop after saving the episode under way: Esc")
async def stop_recording(service: Service) -> RecordingState:
    """As Esc in ``poppy dataset record``; the saved episodes stay in the dataset."""
    return RecordingState(**service.recordings.press(ESC))
