"""v1: release the motors (ports closed, for another program) and take them back."""

from fastapi import APIRouter  # noqa: TID253 (the server room is FastAPI's)
from pydantic import BaseModel
from starlette.concurrency import run_in_threadpool

from poppy_core.errors import PortError
from poppy_core.server import access
from poppy_core.server.deps import Service
from poppy_core.server.errors import ApiError
from poppy_core.server.schemas import Problem

router = APIRouter(
    tags=["motor access"], responses={409: {"model": Problem}, 503: {"model": Problem}}
)


class NoMotors(BaseModel):
    """A bus where no motor answers (the robot keeps looking for them)."""

    port: str
    message: str


class Access(BaseModel):
    """Whether the robot holds its motors' ports."""

    released: bool
    ports: list[str]
    no_motors: list[NoMotors]


class Released(Access):
    """What releasing the motors stopped."""

    primitives: list[str]
    moves: list[str]


@router.get("/motors/access", summary="Released or not; buses where no motor answers")
async def access_route(service: Service) -> Access:
    """Whether the ports are closed (released) and which buses have no motor answering."""
    return Access(**await run_in_threadpool(access.access_state, service))


@router.post("/motors/release", summary="Release the motors: stop all, compliant, ports closed")
async def release_route(service: Service) -> Released:
    """Stop every primitive and move, make the motors compliant and close the ports so that
    another program (a notebook, `poppy scan`) can open them. ``/motors/take`` takes them back."""
    return Released(**await run_in_threadpool(access.release_motors, service))


@router.post("/motors/take", summary="Take the motors back: reopen the ports")
async def take_route(service: Service) -> Access:
    """Reopen the ports released and find the motors again (they stay compliant). 409 while
    another program holds a port."""
    try:
        state = await run_in_threadpool(access.take_motors, service)
    except PortError as exc:
        raise ApiError(
            "conflict", str(exc), tip="close the program using the port, then take them again"
        ) from None
    return Access(**state)
