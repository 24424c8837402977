"""pypot's routes for recorded moves (``/records``) and primitives (``/primitives``)."""

from typing import Any

from fastapi import APIRouter, Request  # noqa: TID253 (the server room is FastAPI's)
from fastapi.responses import Response  # noqa: TID253
from starlette.concurrency import run_in_threadpool

from poppy_core import checks
from poppy_core.errors import ArgumentError
from poppy_core.server.deps import Service
from poppy_core.server.errors import ApiError
from poppy_core.server.moves import pypot_positions
from poppy_core.server.pypot_json import PypotJSON
from poppy_core.server.routers.common import CHANGES_STATE, client_of, json_body

router = APIRouter(tags=["pypot"])

MOTORS_TIP = (
    'give motors as a list or a comma-separated string: {"motors": ["m1", "m2"]} or '
    '{"motors": "m1,m2"}'
)
SPEED_TIP = 'the speed is a number, negative to play backwards, e.g. {"speed": "-1.0"}'
# IN ORDER: pypot handled requests one after the other on its event loop, and pages written for
# it count on that: puppet-master's move recorder asks for the move list right after posting a
# save, and for the running list right after posting a play. Saving and starting a playback are
# therefore done on the event loop (no thread-pool hop), so a request arriving next sees them.


# -- records ---------------------------------------------------------------------------------


@router.get("/records/list.json", summary="The moves of the library")
async def records_list(service: Service) -> PypotJSON:
    """``{"moves": [names]}``."""
    names = await run_in_threadpool(service.moves.names)
    return PypotJSON({"moves": names})


@router.post("/records/{move}/record.json", status_code=202, summary="Start recording a move")
async def record(move: str, request: Request, service: Service) -> PypotJSON:
    """202 ``{move: "recording"}``; the optional body names the motors."""
    data = await json_body(request, default={}, tip=MOTORS_TIP)
    motors: Any = data.get("motors") if isinstance(data, dict) else None
    if isinstance(motors, str):
        motors = [m.strip() for m in motors.split(",") if m.strip()]
    if motors is not None and not (
        isinstance(motors, list) and all(isinstance(m, str) for m in motors)
    ):
        raise ApiError("invalid", "cannot read the motors given", tip=MOTORS_TIP)
    await run_in_threadpool(service.moves.record, move, motors or None)
    return PypotJSON({move: "recording"}, status_code=202)


@router.post("/records/{move}/save.json", status_code=202, summary="Stop recording and save")
async def save(move: str, service: Service) -> PypotJSON:
    """202 ``{move: "saved"}``; 404 when it is not being recorded.

    Saved on the event loop (see IN ORDER above): the list asked for next holds the move.
    """
    service.moves.save(move)
    return PypotJSON({move: "saved"}, status_code=202)


@router.get("/records/{move}/value.json", summary="The frames of a move")
def move_value(move: str, service: Service) -> PypotJSON:
    """``{move: {time: {motor: [position, speed]}}, "length": frames}``."""
    recorded = service.moves.value(move)
    return PypotJSON({move: pypot_positions(recorded), "length": len(recorded)})


@router.post("/records/{move}/play.json", status_code=202, summary="Play a move")
async def play(move: str, request: Request, service: Service) -> PypotJSON:
    """202 ``{move: "started replay"}``; a negative speed plays it backwards."""
    data = await json_body(request, tip=SPEED_TIP)
    if not isinstance(data, dict) or "speed" not in data:
        raise ApiError("invalid", "speed field is missing.", tip=SPEED_TIP)
    try:
        speed = checks.number_from(data["speed"], "speed")
    except ArgumentError as exc:
        raise ApiError("invalid", str(exc), tip=SPEED_TIP) from None
    if speed == 0:
        raise ApiError("invalid", "the speed must be a finite, non-zero number", tip=SPEED_TIP)
    # on the event loop: see IN ORDER above; pypot's play is never refused (no writer)
    service.moves.play(move, abs(speed), speed < 0, client=client_of(request))
    return PypotJSON({move: "started replay"}, status_code=202)


@router.post("/records/{move}/stop.json", status_code=202, summary="Stop playing a move")
def stop(move: str, service: Service) -> PypotJSON:
    """202 ``{move: "stopped"}``; 400 when it was never played."""
    service.moves.stop(move)
    return PypotJSON({move: "stopped"}, status_code=202)


@router.post("/records/{move}/delete.json", status_code=202, summary="Delete a move")
def delete(move: str, service: Service) -> PypotJSON:
    """202 ``{move: "deleted"}``; 404 when there is no such move."""
    service.moves.delete(move)
    return PypotJSON({move: "deleted"}, status_code=202)


# -- primitives ------------------------------------------------------------------------------


@router.get("/primitives/list.json", summary="The attached primitives")
async def primitives_list(service: Service) -> PypotJSON:
    """``{"primitives": [names]}``."""
    return PypotJSON({"primitives": list(service.primitives())})


@router.get("/primitives/running/list.json", summary="The running primitives")
async def running_list(service: Service) -> PypotJSON:
    """``{"running_primitives": [names]}``, with pypot's ``_<move>_recorder``/``_<move>_player``."""
    return PypotJSON({"running_primitives": service.pypot_running_primitives()})


PAST = {"start": "started", "stop": "stopped", "pause": "paused", "resume": "resumed"}


def _control(primitive: str, action: str, service: Any) -> PypotJSON:
    service.control_primitive(primitive, action)
    return PypotJSON({primitive: PAST[action]}, status_code=202)


@router.get(
    "/primitives/{primitive}/start.json",
    status_code=202,
    summary="Start a primitive",
    openapi_extra=CHANGES_STATE,
)
def start_primitive(primitive: str, service: Service) -> PypotJSON:
    """202 ``{primitive: "started"}``."""
    return _control(primitive, "start", service)


@router.get(
    "/primitives/{primitive}/stop.json",
    status_code=202,
    summary="Stop a primitive",
    openapi_extra=CHANGES_STATE,
)
def stop_primitive(primitive: str, service: Service) -> PypotJSON:
    """202 ``{primitive: "stopped"}``."""
    return _control(primitive, "stop", service)


@router.get(
    "/primitives/{primitive}/pause.json",
    status_code=202,
    summary="Pause a primitive",
    openapi_extra=CHANGES_STATE,
)
def pause_primitive(primitive: str, service: Service) -> PypotJSON:
    """202 ``{primitive: "paused"}``."""
    return _control(primitive, "pause", service)


@router.get(
    "/primitives/{primitive}/resume.json",
    status_code=202,
    summary="Resume a primitive",
    openapi_extra=CHANGES_STATE,
)
def resume_primitive(primitive: str, service: Service) -> PypotJSON:
    """202 ``{primitive: "resumed"}``."""
    return _control(primitive, "resume", service)


@router.get("/primitives/{primitive}/properties/list.json", summary="A primitive's properties")
async def properties_list(primitive: str, service: Service) -> PypotJSON:
    """``{"property": [names]}`` (pypot's key)."""
    return PypotJSON({"property": service.property_names(primitive)})


@router.get(
    "/primitives/{primitive}/properties/{prop}/value.json", summary="Read a primitive property"
)
async def get_property(primitive: str, prop: str, service: Service) -> PypotJSON:
    """``{"primitive.prop": value}``."""
    return PypotJSON({f"{primitive}.{prop}": service.get_property(primitive, prop)})


@router.post(
    "/primitives/{primitive}/properties/{prop}/value.json",
    status_code=204,
    summary="Write a primitive property (the body is the raw JSON value)",
)
async def set_property(primitive: str, prop: str, request: Request, service: Service) -> Response:
    """204 with no body."""
    data = await json_body(request, tip="the body is the new value as JSON")
    service.set_property(primitive, prop, data)
    return Response(status_code=204)


@router.get("/primitives/{primitive}/methods/list.json", summary="A primitive's methods")
async def methods_list(primitive: str, service: Service) -> PypotJSON:
    """``{"methods": [names]}``."""
    return PypotJSON({"methods": service.method_names(primitive)})


@router.post(
    "/primitives/{primitive}/methods/{method}/args.json", summary="Call a primitive method"
)
async def call_method(primitive: str, method: str, request: Request, service: Service) -> PypotJSON:
    """``{"primitive:method": result}``; the body holds the keyword arguments (or a list)."""
    data = await json_body(request, default={}, tip="the body is an object of keyword arguments")
    args, kwargs = (data, {}) if isinstance(data, list) else ([], data)
    if not isinstance(kwargs, dict):
        args, kwargs = [data], {}
    result = await run_in_threadpool(service.call_method, primitive, method, args, kwargs)
    return PypotJSON({f"{primitive}:{method}": result})
