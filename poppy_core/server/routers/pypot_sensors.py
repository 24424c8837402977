"""pypot's sensor routes: list, registers, values, the camera's frame, marker codes."""

from fastapi import APIRouter, Request  # noqa: TID253 (the server room is FastAPI's)
from fastapi.responses import Response  # noqa: TID253
from starlette.concurrency import run_in_threadpool

from poppy_core.server.errors import ApiError
from poppy_core.server.pypot_json import PypotJSON
from poppy_core.server.sensors import IMAGE_TYPES, SensorService

router = APIRouter(tags=["pypot"])


def sensors_of(request: Request) -> SensorService:
    """The sensor service ``create_app`` stored on the app."""
    service = request.app.state.sensors
    assert isinstance(service, SensorService)
    return service


@router.get("/sensors/list.json", summary="The sensor names")
async def sensors_list(request: Request) -> PypotJSON:
    """``{"sensors": [names]}``."""
    return PypotJSON({"sensors": sensors_of(request).names()})


@router.get("/sensors/code/list.json", summary="The ids of the markers in view")
async def codes_list(request: Request) -> PypotJSON:
    """``{"codes": [ids]}`` (pypot's marker detector route)."""
    markers = await run_in_threadpool(sensors_of(request).markers)
    return PypotJSON({"codes": [m["id"] for m in markers]})


@router.get("/sensors/code/{card}.json", summary="Is a card (caribou, tetris, lapin) in view")
async def code_found(card: str, request: Request) -> PypotJSON:
    """``{"found": true|false}``; 404 for an unknown card."""
    found = await run_in_threadpool(sensors_of(request).sees, card)
    return PypotJSON({"found": found})


@router.get("/sensors/{sensor}/registers/list.json", summary="The registers of a sensor")
async def sensor_registers(sensor: str, request: Request) -> PypotJSON:
    """``{"registers": [names]}``."""
    return PypotJSON({"registers": sensors_of(request).registers(sensor)})


@router.get("/sensors/{sensor}/registers/{register}/value.json", summary="Read a sensor")
async def get_sensor_register(sensor: str, register: str, request: Request) -> PypotJSON:
    """``{register: value}`` (a frame is described; its image is at ``frame.png``)."""
    value = await run_in_threadpool(sensors_of(request).read, sensor, register)
    return PypotJSON({register: value})


@router.post("/sensors/{sensor}/registers/{register}/value.json", summary="Write a sensor")
async def set_sensor_register(sensor: str, register: str, request: Request) -> PypotJSON:
    """404 unknown; 400 otherwise: the sensors' registers are read-only."""
    if register not in sensors_of(request).registers(sensor):
        await run_in_threadpool(sensors_of(request).read, sensor, register)  # raises not found
    raise ApiError(
        "invalid",
        f"register '{register}' of sensor '{sensor}' is read-only",
        tip="the sensors' registers can only be read",
    )


@router.get("/sensors/{sensor}/frame.{ext}", summary="The camera's latest frame (png or jpg)")
async def frame_image(sensor: str, ext: str, request: Request) -> Response:
    """The image; 404 unknown camera or format; 503 no frame (camera lost)."""
    data = await run_in_threadpool(sensors_of(request).image, sensor, ext)
    return Response(data, media_type=IMAGE_TYPES[ext], headers={"Cache-Control": "no-store"})
