"""pypot's routes for the robot, motors, registers and gotos (same paths and shapes)."""

import html
import socket

from fastapi import APIRouter, Request  # noqa: TID253 (the server room is FastAPI's)
from fastapi.responses import HTMLResponse  # noqa: TID253

from poppy_core.server.deps import Service
from poppy_core.server.errors import ApiError
from poppy_core.server.pypot_goto import GOTOS_TIP, goto_number, goto_request
from poppy_core.server.pypot_json import PypotJSON
from poppy_core.server.pypot_values import pypot_value
from poppy_core.server.routers.common import json_body, truthy, wait_goto

router = APIRouter(tags=["pypot"])

GOTO_TIP = (
    '"position" (degrees) and "duration" (seconds) are required, "wait" is optional. '
    'Example: {"position": 90, "duration": 3, "wait": true}'
)


@router.get("/routes", response_class=HTMLResponse, summary="The routes of the API")
async def index(request: Request) -> HTMLResponse:
    """Every route, as pypot's server listed them at ``/`` (``/`` is now the home page)."""
    lines = ["<b>All url paths available:</b><br>"]
    for path, operations in request.app.openapi()["paths"].items():
        methods = ", ".join(m.upper() for m in operations)
        lines.append(f"{methods} {html.escape(path)}<br>")
    lines.append("WEBSOCKET /api/v1/ws<br>")
    return HTMLResponse("\n".join(lines))


@router.get("/robot.json", summary="Every motor's registers and every primitive")
async def robot_json(service: Service) -> PypotJSON:
    """pypot's robot description (also answered by the fast path)."""
    return PypotJSON(service.description())


# TEST-NET-1 (RFC 5737): connecting a UDP socket there only picks the outgoing interface, no
# packet is sent (pypot asks the same of 8.8.8.8).
ROUTE_PROBE = ("192.0.2.1", 9)


def local_ip() -> str | None:
    """The address other machines reach this one at (the default route's), None if none."""
    try:
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:
            probe.connect(ROUTE_PROBE)
            return str(probe.getsockname()[0])
    except OSError:
        return None


@router.get("/ip.json", summary="The robot's IP address")
def ip_json() -> PypotJSON:
    """``{"ip": address}`` as pypot; 404 with an error and a tip when there is no network."""
    ip = local_ip()
    if ip is None:
        return PypotJSON(
            {
                "error": "Cannot find ip of your Poppy Robot",
                "tip": "this machine has no network route: check its connection (ip addr)",
            },
            status_code=404,
        )
    return PypotJSON({"ip": ip})


@router.get("/motors/list.json", summary="The motor names")
async def motors_list(service: Service) -> PypotJSON:
    """``{"motors": [names]}``."""
    return PypotJSON({"motors": service.motor_names()})


@router.get("/motors/aliases/list.json", summary="The group names")
async def aliases_list(service: Service) -> PypotJSON:
    """``{"aliases": [group names]}``."""
    return PypotJSON({"aliases": list(service.groups())})


@router.get("/motors/registers/{register}/list.json", summary="One register of every motor")
async def register_values(register: str, service: Service) -> PypotJSON:
    """``{register: {motor: value}}``."""
    return PypotJSON({register: service.register_values(register)})


@router.get("/motors/{alias}/list.json", summary="The motors of a group")
async def alias_list(alias: str, service: Service) -> PypotJSON:
    """``{alias: [names]}``."""
    return PypotJSON({alias: service.group(alias)})


@router.get("/motors/{motor}/registers/list.json", summary="The registers of a motor")
async def registers_list(motor: str, service: Service) -> PypotJSON:
    """``{"registers": [names]}``."""
    return PypotJSON({"registers": list(service.motor(motor).registers)})


@router.get("/motors/{motor}/registers/{register}/value.json", summary="Read a register")
async def get_register(motor: str, register: str, service: Service) -> PypotJSON:
    """``{register: value}``."""
    return PypotJSON({register: service.read(motor, register)})


@router.post(
    "/motors/{motor}/registers/{register}/value.json",
    status_code=202,
    summary="Write a register (the body is the raw JSON value)",
)
async def set_register(motor: str, register: str, request: Request, service: Service) -> PypotJSON:
    """202 ``{register: value}``; 404 unknown motor/register; 400 bad or read-only value."""
    data = await json_body(request, tip="the body is the new value as JSON, e.g. 90 or true")
    value = service.write(motor, register, pypot_value(motor, register, data))
    return PypotJSON({register: value}, status_code=202)


@router.post("/motors/{motor}/goto.json", status_code=202, summary="Move one motor")
async def motor_goto(motor: str, request: Request, service: Service) -> PypotJSON:
    """202 ``{"motors": {motor: position}, "duration", "waiting"}`` (after the move if waiting)."""
    data = await json_body(request, tip=GOTO_TIP)
    if not isinstance(data, dict) or "position" not in data or "duration" not in data:
        raise ApiError("invalid", "cannot read the data given", tip=GOTO_TIP)
    position = goto_number(data["position"], "position", GOTO_TIP)
    duration = goto_number(data["duration"], "duration", GOTO_TIP)
    wait = truthy(data.get("wait", False))
    handle = service.goto({motor: position}, duration)
    if wait:
        await wait_goto(handle)
    return PypotJSON(
        {"motors": {motor: position}, "duration": duration, "waiting": wait}, status_code=202
    )


@router.post("/motors/goto.json", status_code=202, summary="Move several motors together")
async def motors_goto(request: Request, service: Service) -> PypotJSON:
    """202 ``{"motors": {motor: position}, "duration", "waiting"}``."""
    targets, duration, wait = goto_request(await json_body(request, tip=GOTOS_TIP))
    handle = service.goto(targets, duration)
    if wait:
        await wait_goto(handle)
    return PypotJSON({"motors": targets, "duration": duration, "waiting": wait}, status_code=202)
