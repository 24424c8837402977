"""v1: sensors (registers, health), camera frames, an MJPEG stream for browsers, markers."""

import asyncio
from collections.abc import AsyncIterator
from typing import Any

from fastapi import APIRouter, Query, Request  # noqa: TID253 (the server room is FastAPI's)
from fastapi.responses import Response, StreamingResponse  # noqa: TID253
from starlette.concurrency import run_in_threadpool

from poppy_core import checks
from poppy_core.errors import SensorError
from poppy_core.sensors import Camera
from poppy_core.sensors.camera import JPEG_QUALITY
from poppy_core.server.routers.pypot_sensors import sensors_of
from poppy_core.server.schemas import Problem
from poppy_core.server.sensors import IMAGE_TYPES

router = APIRouter(tags=["sensors"], responses={404: {"model": Problem}, 503: {"model": Problem}})

BOUNDARY = "frame"
MJPEG_QUALITY = JPEG_QUALITY
"""The snapshots', ROS 2's and Foxglove's quality too: one JPEG of a frame serves them all."""
FRAME_WAIT_S = 5.0
LOST_CAMERA_RETRY_S = 0.5
"""The stream's pause before asking a failed camera again (it may fail at once every time)."""
MIN_FPS, MAX_FPS = 0.1, 60.0


@router.get("/sensors", summary="Every sensor: type, registers, health")
async def sensors(request: Request) -> list[dict[str, Any]]:
    """One entry per sensor, in config order."""
    service = sensors_of(request)
    return [
        {
            "name": s.name,
            "type": s.kind,
            "registers": list(s.registers),
            "health": s.health().as_dict(),
        }
        for s in service.robot.sensors
    ]


@router.get("/sensors/health", summary="Sensor name -> its health")
async def sensors_health(request: Request) -> dict[str, dict[str, object]]:
    """Connected, rate, errors, age of the latest value, per sensor."""
    return sensors_of(request).health()


@router.get("/sensors/{sensor}", summary="A sensor's registers (a frame described) and health")
async def sensor(sensor: str, request: Request) -> dict[str, Any]:
    """Reading may wait for the sensor's first value (a camera's first frame)."""
    return await run_in_threadpool(sensors_of(request).describe, sensor)


@router.get(
    "/sensors/{sensor}/frame.{ext}",
    summary="A camera's latest frame (png or jpg)",
    response_class=Response,
    responses={200: {"content": {"image/png": {}, "image/jpeg": {}}}},
)
async def frame(sensor: str, ext: str, request: Request) -> Response:
    """The image of the latest frame."""
    data = await run_in_threadpool(sensors_of(request).image, sensor, ext)
    return Response(data, media_type=IMAGE_TYPES[ext], headers={"Cache-Control": "no-store"})


async def mjpeg(camera: Camera, request: Request, fps: float) -> AsyncIterator[bytes]:
    """Parts of a ``multipart/x-mixed-replace`` stream: each new frame as a JPEG.

    A viewer waits for frames in the event loop and shares each frame's one JPEG with the
    others (``Camera.wait_frame``, ``Camera.encoded_async``): hundreds of viewers hold no
    thread of the pool the other routes run in.
    """
    period = 1.0 / fps
    number = 0
    loop = asyncio.get_running_loop()
    due = loop.time()
    # no request.is_disconnected() per part (hundreds of viewers: its cost shows): a client that
    # leaves ends the stream by itself (Starlette cancels it on the disconnect message, or
    # sending it the next part fails)
    while True:
        try:
            latest = await camera.wait_frame(number, FRAME_WAIT_S)
        except SensorError:
            # a lost camera: keep the connection, frames come back with it; a camera that
            # failed for good answers at once, so wait before asking again (no spinning)
            await asyncio.sleep(max(period, LOST_CAMERA_RETRY_S))
            if await request.is_disconnected():  # nothing is sent meanwhile: ask
                return
            due = loop.time()
            continue
        number = latest.number
        jpeg = await camera.encoded_async(latest, ".jpg", MJPEG_QUALITY)
        yield (
            (
                f"--{BOUNDARY}\r\nContent-Type: image/jpeg\r\nContent-Length: {len(jpeg)}\r\n\r\n"
            ).encode()
            + jpeg
            + b"\r\n"
        )
        # parts due every period from the first: the wait for a frame does not add to it, and
        # after a stall at most one part comes early (no burst to catch up)
        due = max(due + period, loop.time() - period)
        await asyncio.sleep(max(0.0, due - loop.time()))


@router.get(
    "/sensors/{sensor}/stream.mjpg",
    summary="A camera as an MJPEG stream (an <img src=...> in a browser)",
    response_class=StreamingResponse,
    responses={200: {"content": {f"multipart/x-mixed-replace; boundary={BOUNDARY}": {}}}},
)
async def stream(
    sensor: str,
    request: Request,
    fps: float = Query(15.0, description=f"Frames per second at most ({MIN_FPS:g}-{MAX_FPS:g})."),
) -> StreamingResponse:
    """Every new frame as a JPEG part, at most ``fps`` per second, until the client leaves."""
    fps = checks.in_range(fps, MIN_FPS, MAX_FPS, "fps", "Hz")  # NaN, 0, 1e-300: a 422
    camera = sensors_of(request).camera(sensor)
    health = camera.health()
    if not health.connected:  # unplugged or busy: a 503 now, not a stream of nothing
        raise SensorError(
            f"camera {sensor!r} is not available now: {health.last_error}", sensor=sensor
        )
    await run_in_threadpool(camera.latest)  # the first frame (or a 503 now, not mid-stream)
    return StreamingResponse(
        mjpeg(camera, request, fps),
        media_type=f"multipart/x-mixed-replace; boundary={BOUNDARY}",
        headers={"Cache-Control": "no-store"},
    )


@router.get("/markers", summary="The markers in view (ids, families, positions, poses)")
async def markers(request: Request) -> list[dict[str, Any]]:
    """What the marker detector sees now."""
    return await run_in_threadpool(sensors_of(request).markers)


@router.get("/markers/cards/{card}", summary="Is a card (caribou, tetris, lapin) or id in view")
async def card(card: str, request: Request) -> dict[str, Any]:
    """``{"card", "found"}`` (the library call behind Snap!'s ``/detect/<card>``)."""
    found = await run_in_threadpool(sensors_of(request).sees, card)
    return {"card": card, "found": found}
