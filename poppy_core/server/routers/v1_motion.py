"""v1: gotos, primitives and moves."""

from functools import partial

from fastapi import APIRouter, Query  # noqa: TID253 (the server room is FastAPI's)
from starlette.concurrency import run_in_threadpool
from starlette.requests import Request

from poppy_core.server.deps import Service
from poppy_core.server.routers.common import V1_WRITER, client_of, wait_goto
from poppy_core.server.schemas import (
    GotoRequest,
    GotoResult,
    LibraryMoveInfo,
    MethodCall,
    MethodResult,
    MoveInfo,
    MovesStatus,
    PlayRequest,
    PrimitiveInfo,
    Problem,
    RecordRequest,
    StartRequest,
    ValueBody,
)

ERRORS: dict[int | str, dict[str, object]] = {
    404: {"model": Problem},
    409: {"model": Problem},
    422: {"model": Problem},
}
router = APIRouter(responses=ERRORS)


# -- gotos -----------------------------------------------------------------------------------


@router.post("/gotos", tags=["gotos"], summary="Move motors so that they arrive together")
async def goto(body: GotoRequest, service: Service) -> GotoResult:
    """Starts the motion; with ``wait`` answers once it is over (other requests go on)."""
    targets = service.targets(body.positions)  # clamped to the angle limits: the answer says so
    handle = service.goto(
        targets, body.duration_s, body.control, refuse_compliant=True, writer=V1_WRITER
    )
    waited = await wait_goto(handle) if body.wait else False
    return GotoResult(
        positions=targets,
        duration_s=body.duration_s,
        control=body.control,
        waited=body.wait,
        done=handle.done or waited,
    )


# -- primitives ------------------------------------------------------------------------------


def _primitive(service: Service, name: str) -> PrimitiveInfo:
    return PrimitiveInfo.model_validate(service.describe_primitive(name))


@router.get("/primitives", tags=["primitives"], summary="Every attached primitive")
async def primitives(service: Service) -> list[PrimitiveInfo]:
    """State, properties and methods of each."""
    return [_primitive(service, name) for name in service.primitives()]


@router.get("/primitives/{primitive}", tags=["primitives"], summary="One primitive")
async def primitive(primitive: str, service: Service) -> PrimitiveInfo:
    """Its state, properties, methods and last error."""
    return _primitive(service, primitive)


def _control(
    service: Service, name: str, action: str, start_at: float | None = None
) -> PrimitiveInfo:
    service.control_primitive(name, action, start_at=start_at)
    return _primitive(service, name)


@router.post("/primitives/{primitive}/start", tags=["primitives"], summary="Start (or restart)")
def start(primitive: str, service: Service, body: StartRequest | None = None) -> PrimitiveInfo:
    """Starts the primitive's thread (with a ``start_at``: armed now, started then)."""
    return _control(service, primitive, "start", body.start_at if body is not None else None)


@router.post("/primitives/{primitive}/stop", tags=["primitives"], summary="Stop")
def stop(primitive: str, service: Service) -> PrimitiveInfo:
    """Stops it and waits for its thread."""
    return _control(service, primitive, "stop")


@router.post("/primitives/{primitive}/pause", tags=["primitives"], summary="Pause")
def pause(primitive: str, service: Service) -> PrimitiveInfo:
    """Pauses a running primitive."""
    return _control(service, primitive, "pause")


@router.post("/primitives/{primitive}/resume", tags=["primitives"], summary="Resume")
def resume(primitive: str, service: Service) -> PrimitiveInfo:
    """Resumes a paused primitive."""
    return _control(service, primitive, "resume")


@router.put(
    "/primitives/{primitive}/properties/{prop}", tags=["primitives"], summary="Set a property"
)
async def set_property(
    primitive: str, prop: str, body: ValueBody, service: Service
) -> PrimitiveInfo:
    """Converted to the property's type and checked by the primitive."""
    service.set_property(primitive, prop, body.value)
    return _primitive(service, primitive)


@router.post(
    "/primitives/{primitive}/methods/{method}", tags=["primitives"], summary="Call a method"
)
def call(primitive: str, method: str, body: MethodCall, service: Service) -> MethodResult:
    """Calls a declared method with ``args`` (positional) and ``kwargs``."""
    return MethodResult(result=service.call_method(primitive, method, body.args, body.kwargs))


# -- moves -----------------------------------------------------------------------------------


@router.get("/moves", tags=["moves"], summary="The moves of the library")
def moves(service: Service) -> list[LibraryMoveInfo]:
    """Name, format, size, duration and frames of each."""
    return [LibraryMoveInfo.model_validate(e) for e in service.moves.entries()]


@router.get("/moves/status", tags=["moves"], summary="Moves being recorded and played")
async def moves_status(service: Service) -> MovesStatus:
    """Names of the recordings and playbacks running."""
    return MovesStatus(recording=service.moves.recording(), playing=service.moves.playing())


@router.get("/moves/{move}", tags=["moves"], summary="A move (being recorded, else the library's)")
def move(
    move: str,
    service: Service,
    positions: bool = Query(False, description="include the frames (degrees)"),
) -> MoveInfo:
    """Its motors, frames and duration."""
    found = service.moves.value(move)
    return MoveInfo(
        name=move,
        framerate=found.framerate,
        motors=list(found.motors),
        frames=len(found),
        duration_s=found.duration_s,
        positions=found.positions.tolist() if positions else None,
    )


@router.delete("/moves/{move}", tags=["moves"], status_code=204, summary="Delete a move")
def delete(move: str, service: Service) -> None:
    """Removes it from the library."""
    service.moves.delete(move)


@router.post("/moves/{move}/record", tags=["moves"], status_code=202, summary="Start recording")
async def record(move: str, body: RecordRequest, service: Service) -> MovesStatus:
    """Records the motors (or groups) named, every motor by default, until ``save``."""
    await run_in_threadpool(service.moves.record, move, body.motors)
    return await moves_status(service)


@router.post("/moves/{move}/save", tags=["moves"], summary="Stop recording and save")
def save(move: str, service: Service) -> MoveInfo:
    """Saves the recording to the library."""
    saved = service.moves.save(move)
    return MoveInfo(
        name=move,
        framerate=saved.framerate,
        motors=list(saved.motors),
        frames=len(saved),
        duration_s=saved.duration_s,
    )


@router.post("/moves/{move}/play", tags=["moves"], status_code=202, summary="Play a move")
async def play(move: str, body: PlayRequest, service: Service, request: Request) -> MovesStatus:
    """Starts playing; a move already playing, or one whose motors another owner drives
    (teleop, another move, a trajectory...), is refused (409): stop it first."""
    await run_in_threadpool(
        partial(
            service.moves.play,
            start_at=body.start_at,
            writer=V1_WRITER,
            client=client_of(request),
        ),
        move,
        body.speed,
        body.backwards,
        body.ramp_s,
        True,  # refuse_playing
    )
    return await moves_status(service)


@router.post("/moves/{move}/stop", tags=["moves"], summary="Stop playing a move")
def stop_move(move: str, service: Service) -> MovesStatus:
    """Stops the playback (the motors stay stiff where they are)."""
    service.moves.stop(move)
    return MovesStatus(recording=service.moves.recording(), playing=service.moves.playing())
