"""``create_app(robot)``: the FastAPI app serving a robot (home page, pypot routes, v1, WS)."""

from __future__ import annotations

import inspect
from collections.abc import AsyncIterator
from contextlib import asynccontextmanager
from typing import TYPE_CHECKING, Any
from urllib.parse import urlencode

from starlette.requests import Request
from starlette.responses import HTMLResponse

from poppy_core.server.errors import install_error_handlers
from poppy_core.server.fastpath import RegisterFastPath
from poppy_core.server.legacy_paths import LegacyPaths
from poppy_core.server.middleware import MAX_BODY_BYTES, BodyLimitMiddleware, TokenMiddleware
from poppy_core.server.origin_guard import OriginGuard
from poppy_core.server.origins import OriginPolicy
from poppy_core.server.service import RobotService
from poppy_core.server.state_routes import changes_state_as_routed
from poppy_core.server.web import add_web_page, is_public

if TYPE_CHECKING:
    from fastapi import FastAPI

    from poppy_core.robot import Robot

API_VERSION = "1.0"
DEFAULT_STREAM_HZ = 30.0


def create_app(
    robot: Robot,
    *,
    token: str | None = None,
    policy: OriginPolicy | None = None,
    max_body_bytes: int = MAX_BODY_BYTES,
    stream_rate_hz: float = DEFAULT_STREAM_HZ,
    builtins: bool = True,
    service: RobotService | None = None,
) -> FastAPI:
    """Build the app serving ``robot`` (which the caller keeps and closes).

    Args:
        robot: the robot to serve.
        token: when set, every route and the WebSocket need it (Bearer header or ``?token=``).
        policy: the Host names and browser origins accepted (see ``origins``); by default
            loopback names, IP addresses and the server's own pages only.
        max_body_bytes: largest request body accepted (413 beyond).
        stream_rate_hz: default rate of the WebSocket state stream.
        builtins: attach the built-in primitives to the robot.
        service: the robot service shared with the other servers of the robot
            (``poppy_core.assembly.serve``), which closes it; by default the app makes its own.

    Returns:
        The app; its lifespan stops the recordings and playbacks of its own service on shutdown.
    """
    from poppy_core.server.front import GuardedAPI
    from poppy_core.server.routers import (
        pypot_ik,
        pypot_motion,
        pypot_motors,
        pypot_sensors,
        v1_access,
        v1_chains,
        v1_motion,
        v1_motors,
        v1_recording,
        v1_robot,
        v1_sensors,
        v1_settings,
    )
    from poppy_core.server.sensors import SensorService
    from poppy_core.server.settings import RobotSettings
    from poppy_core.server.stream import add_stream_routes

    owns_service = service is None
    service = service or RobotService(robot, builtins=builtins)

    @asynccontextmanager
    async def lifespan(app: FastAPI) -> AsyncIterator[None]:
        app.state.web_logs.attach()
        try:
            yield
        finally:
            app.state.web_logs.detach()
            if owns_service:
                service.close()

    app = GuardedAPI(
        title="poppy robot API",
        version=API_VERSION,
        description=(
            "pypot-compatible routes (``/robot.json``, ``/motors/...``) and the v1 API under "
            "``/api/v1``. Angles in degrees, speeds in deg/s, durations in seconds."
        ),
        lifespan=lifespan,
        docs_url=None,
        **no_telemetry(GuardedAPI),
    )
    policy = policy or OriginPolicy()
    app.state.service = service
    app.state.sensors = SensorService(robot)
    app.state.policy = policy
    app.state.settings = RobotSettings()
    app.state.settings.served.token_required = bool(token)
    app.state.settings.served.policies = [policy]
    app.state.stream_rate_hz = stream_rate_hz
    install_error_handlers(app)
    add_web_page(app)  # the home page at / (its assets and /api/v1/web)
    # pypot's routes first: the hottest ones (register values) are matched soonest.
    for router in (
        pypot_motors.router,
        pypot_motion.router,
        pypot_ik.router,
        pypot_sensors.router,
    ):
        app.include_router(router)
    for router in (
        v1_robot.router,
        v1_access.router,  # before v1_motors: /motors/access is not a motor named "access"
        v1_motors.router,
        v1_motion.router,
        v1_chains.router,
        v1_recording.router,
        v1_sensors.router,
        v1_settings.router,
    ):
        app.include_router(router, prefix="/api/v1")
    add_stream_routes(app)
    add_docs_route(app)
    app.add_middleware(LegacyPaths)  # innermost: the old spellings reach the routers rewritten
    changes_state = changes_state_as_routed(app)
    # In front of FastAPI's layers (front.py), outermost first: the Host/Origin guard (which
    # GETs change the robot is decided on the route each spelling reaches: LegacyPaths
    # rewrites them later), the token, the body size, then pypot's fast path.
    app.guard(
        lambda inner: OriginGuard(inner, policy=policy, changes_state=changes_state),
        *([lambda inner: TokenMiddleware(inner, token=token, public=is_public)] if token else []),
        lambda inner: BodyLimitMiddleware(inner, max_bytes=max_body_bytes),
        lambda inner: RegisterFastPath(inner, service=service),
    )
    return app


def add_docs_route(app: FastAPI) -> None:
    """``/docs``: Swagger UI; a ``?token=`` given to it is passed on to ``/openapi.json``."""
    from fastapi.openapi.docs import get_swagger_ui_html

    async def docs(request: Request) -> HTMLResponse:
        token = request.query_params.get("token")
        url = "/openapi.json" + (f"?{urlencode({'token': token})}" if token else "")
        return get_swagger_ui_html(openapi_url=url, title=f"{app.title} - docs")

    app.add_api_route("/docs", docs, include_in_schema=False, methods=["GET"])


NO_TELEMETRY = {"tracing": False, "metrics": False, "logs": False}


def no_telemetry(fastapi: type) -> dict[str, Any]:
    """``FastAPI(telemetry=...)`` turning its OpenTelemetry support off, where FastAPI has one.

    poppy exports no traces or metrics; FastAPI 0.16x otherwise asks OpenTelemetry for its three
    global providers (three ``os.environ`` lookups) on every request: about 1 µs of a register
    read's 60 (docs/performance.md, REST server). Older FastAPI has no such argument.
    """
    parameters = inspect.signature(fastapi).parameters
    return {"telemetry": dict(NO_TELEMETRY)} if "telemetry" in parameters else {}
