"""The web page's own routes under ``/api/v1/web``: who the robot is, motor details, logs, Stop.

Everything else the page does goes through the ordinary v1 API (motors, primitives, moves,
chains, sensors, the WebSocket stream); these routes gather what the page needs at once.
"""

from __future__ import annotations

import logging
import time
from typing import Any, Literal

from fastapi import APIRouter, Query, Request  # noqa: TID253 (the server room is FastAPI's)
from pydantic import BaseModel, Field
from starlette.concurrency import run_in_threadpool

from poppy_core.errors import PoppyError
from poppy_core.robot import Motor, Robot
from poppy_core.sensors import Camera
from poppy_core.server.access import halt_activity
from poppy_core.server.deps import Service
from poppy_core.server.schemas import Problem
from poppy_core.server.service import RobotService
from poppy_core.server.values import jsonable
from poppy_core.server.web.about_parts import camera_views, notebook, robot_name
from poppy_core.server.web.logs import LogBuffer

logger = logging.getLogger(__name__)

router = APIRouter(prefix="/web", tags=["web page"], responses={422: {"model": Problem}})

LED_CHOICES = ("off", "red", "green", "yellow", "blue", "pink", "cyan", "white")
"""LED values the page offers, kept for each motor when its model accepts them."""


class StopRequest(BaseModel):
    """What the motors do once everything is stopped."""

    then: Literal["compliant", "hold"] = Field(
        "compliant", description="compliant: motors let go; hold: stiff where they are"
    )


class StopResult(BaseModel):
    """What Stop stopped."""

    primitives: list[str]
    moves: list[str]
    then: str


def simulated(robot: Robot) -> bool:
    """True when the robot's servos are virtual (emulated, or a MuJoCo simulation)."""
    return bool(robot.emulators) or robot.simulation is not None


def about(robot: Robot, request: Request) -> dict[str, Any]:
    """The page's header: name, creature, buses and sensors with their health, uptime, links."""
    profile = robot.config.profile if robot.config is not None else None
    state = request.app.state
    health = {name: h.as_dict() for name, h in robot.health().items()}
    settings = getattr(state, "settings", None)
    name, creature = robot_name(robot, settings.served.name if settings is not None else None)
    views, no_camera = camera_views(robot)
    return {
        "name": name,
        "creature": creature,
        "description": profile.description if profile else "",
        "simulated": simulated(robot),
        "uptime_s": round(time.monotonic() - state.web_started, 1),
        "buses": jsonable(health),
        "cameras": [s.name for s in robot.sensors if isinstance(s, Camera)],
        "camera_views": views,
        "no_camera": no_camera,
        "sensors": {name: h.as_dict() for name, h in robot.sensor_health().items()},
        "chains": _chain_names(robot),
        "links": dict(state.web_links),
        "notes": dict(getattr(state, "web_notes", {})),
    }


def _chain_names(robot: Robot) -> list[str]:
    from poppy_core.motion.chains import robot_chains

    return list(robot_chains(robot))


def led_values(motor: Motor) -> list[str | bool]:
    """The LED values the motor's model takes: colour names (XL-320), else off/on as booleans."""
    register = motor.model.register("led")
    accepted: list[str | bool] = []
    for value in LED_CHOICES:
        try:
            register.from_si(value)
        except (PoppyError, ValueError, TypeError, KeyError):
            continue
        accepted.append(value)
    return accepted or [False, True]


def motor_details(motor: Motor, owner: str | None = None) -> dict[str, Any]:
    """What the stream does not send: goal, voltage, compliance, online, limits, and who
    drives its goal (``owner``: a lease's label, ``motion/leases.py``)."""
    return {
        "owner": owner,
        "id": motor.id,
        "model": motor.model.name,
        "goal_position": jsonable(motor.goal_position),
        "present_voltage": jsonable(motor.present_voltage),
        "compliant": motor.compliant,
        "online": motor.online,
        "angle_limit": jsonable(motor.angle_limit),
    }


def stop_everything(service: RobotService, then: str) -> StopResult:
    """Stop every primitive and move playing, then make the motors compliant or hold them."""
    robot = service.robot
    stopped, moves = halt_activity(service)
    if then == "compliant":
        robot.compliant = True
    else:
        for motor in robot.motors:
            motor.goal_position = motor.present_position  # also cancels a goto under way
        robot.compliant = False
    logger.warning(
        "Stop from the web page: primitives stopped: %s; moves stopped: %s; motors %s",
        ", ".join(stopped) or "none",
        ", ".join(moves) or "none",
        "compliant" if then == "compliant" else "held where they are",
    )
    return StopResult(primitives=stopped, moves=moves, then=then)


@router.get("/about", summary="The robot: name, creature, buses' health, uptime, links")
async def about_route(request: Request, service: Service) -> dict[str, Any]:
    """What the page shows in its header; ``notebook`` (port and path) when a Jupyter answers
    on the address the page reached this server at, else null."""
    answer = about(service.robot, request)
    server = request.scope.get("server")
    answer["notebook"] = await notebook(request.app.state, server[0] if server else None)
    return answer


@router.get("/motors", summary="Each motor's goal, voltage, compliance, limits (LED values)")
async def motors_route(
    service: Service,
    leds: bool = Query(False, description="also the LED values each motor takes"),
) -> dict[str, Any]:
    """The slow columns of the motor table (the stream has the fast ones), in config order,
    and the groups."""
    owners = service.leases.labels()
    motors = {m.name: motor_details(m, owners.get(m.name)) for m in service.robot.motors}
    if leds:
        for motor in service.robot.motors:
            motors[motor.name]["leds"] = led_values(motor)
    return {"motors": motors, "groups": service.groups()}


@router.get("/logs", summary="The last lines the server logged")
async def logs_route(
    request: Request,
    after: int = Query(0, ge=0, description="only lines numbered above this"),
    limit: int = Query(200, ge=1, le=500),
) -> list[dict[str, Any]]:
    """Number, time, level, logger and message of each line, oldest first."""
    buffer: LogBuffer = request.app.state.web_logs
    return buffer.lines(after, limit)


@router.post("/stop", summary="Stop every primitive and move; motors compliant or held")
async def stop_route(body: StopRequest, service: Service) -> StopResult:
    """The web equivalent of "kill all access to motors"."""
    return await run_in_threadpool(stop_everything, service, body.then)
