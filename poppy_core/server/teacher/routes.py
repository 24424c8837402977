"""The teacher's page's API under ``/api/v1/fleet``: the cards, their live stream, the commands
to a selection of robots (with the fleet's shared start) and a camera's frame on demand."""

from __future__ import annotations

import asyncio
import base64
import binascii
import json
import logging
import threading
from typing import TYPE_CHECKING, Any
from urllib.parse import quote

from fastapi import APIRouter, Request  # noqa: TID253 (the server room is FastAPI's)
from pydantic import BaseModel, Field
from starlette.concurrency import run_in_threadpool
from starlette.responses import Response
from starlette.websockets import WebSocket, WebSocketDisconnect

from poppy_core import checks
from poppy_core.checks import MAX_DURATION_S
from poppy_core.errors import ArgumentError
from poppy_core.server.errors import ApiError
from poppy_core.server.middleware import token_protocol
from poppy_core.server.schemas import Problem

if TYPE_CHECKING:
    from poppy_core.remote.zenoh_fleet import Fleet, Outcome
    from poppy_core.server.teacher.watch import FleetWatch

logger = logging.getLogger(__name__)

router = APIRouter(prefix="/fleet", tags=["teacher's page"], responses={422: {"model": Problem}})

PUSH_PERIOD_S = 0.25
"""How often the stream looks for news to send (it sends only when something changed)."""
KEEPALIVE_S = 5.0
"""The stream sends the cards at least this often, news or not (the page sees it is alive)."""
MAX_ROBOTS = 256
FRAME_TIMEOUT_S = 10.0
"""How long a robot has to answer a camera's frame: the first one starts its camera."""


class FleetSelection(BaseModel):
    """The robots a command goes to."""

    robots: list[str] = Field(
        ..., min_length=1, max_length=MAX_ROBOTS, description="robot names (poppy/NAME)"
    )


class FleetPlayRequest(FleetSelection):
    """A move of each robot's library, played by the robots together."""

    move: str = Field(..., min_length=1, max_length=128)
    ramp_s: float | None = Field(
        None,
        ge=0.0,
        le=MAX_DURATION_S,
        description="seconds to reach the first frame, the same on every robot",
    )


class FleetRunRequest(FleetSelection):
    """A primitive started on the robots together."""

    primitive: str = Field(..., min_length=1, max_length=128)


class FleetStopRequest(BaseModel):
    """The robots to stop: every robot here when none are named."""

    robots: list[str] | None = Field(None, max_length=MAX_ROBOTS)


def _fleet(request: Request) -> Fleet:
    fleet: Fleet = request.app.state.fleet
    return fleet


def _names(robots: list[str]) -> list[str]:
    """The robot names, checked (``checks.robot_name``), each once, in the order given."""
    try:
        names = [checks.robot_name(n, "robots") for n in robots]
    except ArgumentError as exc:
        raise ApiError("invalid", str(exc)) from None
    return list(dict.fromkeys(names))


def _answer(outcomes: list[Outcome], start_at: float | None) -> dict[str, Any]:
    return {
        "start_at": start_at,
        "outcomes": [
            {"name": o.name, "ok": o.ok, "status": o.status, "message": o.message} for o in outcomes
        ],
    }


def _command(
    request: Request, names: list[str], path: str, body: Any, *, together: bool
) -> dict[str, Any]:
    """Send the command; a shared start holds the app's ``starts`` lock, so the ``start_at``
    read back from the fleet is its own."""
    fleet = _fleet(request)
    if not together:
        return _answer(fleet.command(names, "POST", path, body, together=False), None)
    starts: threading.Lock = request.app.state.starts
    with starts:
        outcomes = fleet.command(names, "POST", path, body)
        return _answer(outcomes, fleet.last_start_at)


@router.get("/robots", summary="Every robot of the fleet: its card")
def robots(request: Request) -> list[dict[str, Any]]:
    """Name, creature, health, hottest motor, what it runs and plays, its moves, primitives
    and cameras; a robot that left keeps its card (``alive`` false)."""
    watch: FleetWatch = request.app.state.watch
    return watch.snapshot()


@router.post("/play", summary="Play a move on the robots selected, all starting together")
async def play(body: FleetPlayRequest, request: Request) -> dict[str, Any]:
    """Each robot plays the move of its own library at the fleet's shared start; each answers
    (a refusal in REST's words)."""
    data: dict[str, Any] = {"speed": 1.0, "backwards": False}
    if body.ramp_s is not None:
        data["ramp_s"] = body.ramp_s
    path = f"/api/v1/moves/{quote(body.move, safe='')}/play"
    names = _names(body.robots)
    return await run_in_threadpool(_command, request, names, path, data, together=True)


@router.post("/run", summary="Start a primitive on the robots selected, all together")
async def run(body: FleetRunRequest, request: Request) -> dict[str, Any]:
    """Each robot starts the primitive at the fleet's shared start."""
    path = f"/api/v1/primitives/{quote(body.primitive, safe='')}/start"
    names = _names(body.robots)
    return await run_in_threadpool(_command, request, names, path, None, together=True)


@router.post("/stop", summary="Stop: primitives and moves stopped, motors held, on every robot")
async def stop(body: FleetStopRequest, request: Request) -> dict[str, Any]:
    """Every robot here (or those named): the robot page's Stop, at once (no shared start)."""
    watch: FleetWatch = request.app.state.watch
    fleet = _fleet(request)
    if body.robots is not None:
        names = _names(body.robots)
    else:
        names = sorted(set(watch.alive()) | set(await run_in_threadpool(fleet.names)))
    if not names:
        raise ApiError("conflict", "no robot on Zenoh to stop")
    path = "/api/v1/web/stop"
    return await run_in_threadpool(_command, request, names, path, {"then": "hold"}, together=False)


@router.get(
    "/robots/{name}/cameras/{camera}/frame.jpg",
    summary="A camera's latest frame, asked of the robot over Zenoh",
    response_class=Response,
    responses={200: {"content": {"image/jpeg": {}}}},
)
async def frame(name: str, camera: str, request: Request) -> Response:
    """Asked only when the page's button is clicked (the robot's v1 frame route, over Zenoh)."""
    robot = _names([name])[0]
    path = f"/api/v1/sensors/{quote(camera, safe='')}/frame.jpg"

    def ask() -> Outcome:
        fleet = _fleet(request)
        timeout_s = max(fleet.timeout_s, FRAME_TIMEOUT_S)
        return fleet.command([robot], "GET", path, together=False, timeout_s=timeout_s)[0]

    outcome = await run_in_threadpool(ask)
    if not outcome.ok:
        raise ApiError(
            "not_found" if outcome.status == 404 else "unavailable", f"{robot}: {outcome.message}"
        )
    answer = outcome.answer
    try:
        data = base64.b64decode(answer["base64"], validate=True)
    except (TypeError, KeyError, ValueError, binascii.Error):
        raise ApiError("unavailable", f"{robot}: its answer is not a picture") from None
    return Response(data, media_type="image/jpeg", headers={"Cache-Control": "no-store"})


async def stream(websocket: WebSocket) -> None:
    """The cards, sent when they change (at most every ``PUSH_PERIOD_S``) and every
    ``KEEPALIVE_S`` anyway, until the page goes."""
    # a page that gave its token as a subprotocol must get it back (browsers require it)
    await websocket.accept(subprotocol=token_protocol(websocket.scope))
    watch: FleetWatch = websocket.app.state.watch
    sent_version = -1
    waited = 0.0
    listener = asyncio.ensure_future(_until_closed(websocket))
    try:
        while not listener.done():
            version = watch.version
            if version != sent_version or waited >= KEEPALIVE_S:
                sent_version, waited = version, 0.0
                text = json.dumps({"robots": watch.snapshot()})
                await websocket.send_text(text)
            await asyncio.wait({listener}, timeout=PUSH_PERIOD_S)
            waited += PUSH_PERIOD_S
    except (WebSocketDisconnect, RuntimeError):
        pass  # the page went while a message was sent
    finally:
        listener.cancel()


async def _until_closed(websocket: WebSocket) -> None:
    """Read (and drop) what the page sends until it closes."""
    while True:
        message = await websocket.receive()
        if message["type"] == "websocket.disconnect":
            return
