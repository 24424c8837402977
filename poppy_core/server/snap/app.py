"""``create_snap_app``: pypot's Snap! routes as a Starlette app answering plain text.

Every route is a GET (Snap!'s ``reportURL``). Reads of cached values and writes that only mark a
register answer from the event loop; what waits (stopping a primitive joins its thread, saving a
move writes a file, a camera frame, an IK solve) runs in the thread pool. Where pypot answers
500 (unknown motor, group, primitive, move or chain; a value that does not parse), this app
answers 404 or 400 with one line of text that a Snap! block can show.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from pathlib import Path
from typing import Any

from starlette.applications import Starlette
from starlette.concurrency import run_in_threadpool
from starlette.requests import Request
from starlette.responses import PlainTextResponse, Response
from starlette.routing import Mount, Route
from starlette.staticfiles import StaticFiles

from poppy_core.errors import PoppyError
from poppy_core.server.errors import PYPOT_STATUS, ApiError, from_poppy_error
from poppy_core.server.refusals import one_line
from poppy_core.server.service import RobotService
from poppy_core.server.snap.blocks import SnapSite
from poppy_core.server.snap.robot import SnapRobot

logger = logging.getLogger(__name__)

TEXT = "text/plain; charset=utf-8"
XML = "application/xml; charset=utf-8"
APP_PREFIX = "/app"
"""Where a local Snap! copy (``--snap-dir``) is served."""

Handler = Callable[[SnapRobot, dict[str, str]], str]


def error_text(exc: Exception) -> tuple[int, str]:
    """Status and one line for a refusal (``Error: ...``, as pypot's blocks show errors)."""
    error = from_poppy_error(exc) if isinstance(exc, PoppyError) else exc
    assert isinstance(error, ApiError)
    status = PYPOT_STATUS[error.kind] if error.kind != "conflict" else 409
    message = one_line(error.message)
    return status, message if message.startswith("Error") else f"Error: {message}"


def text_route(path: str, handler: Handler, *, blocking: bool = False) -> Route:
    """A GET route answering ``handler(snap, path_params)`` as text (errors as one 4xx line)."""

    async def endpoint(request: Request) -> Response:
        snap: SnapRobot = request.app.state.snap
        params = request.path_params
        try:
            if blocking:
                body = await run_in_threadpool(handler, snap, params)
            else:
                body = handler(snap, params)
        except (ApiError, PoppyError) as exc:
            status, line = error_text(exc)
            logger.info("GET %s refused: %s", request.url.path, line)
            return PlainTextResponse(line, status_code=status, media_type=TEXT)
        return PlainTextResponse(body, media_type=TEXT)

    return Route(path, endpoint, methods=["GET"], name=path)


def _control(action: str) -> Handler:
    def handler(snap: SnapRobot, params: dict[str, str]) -> str:
        return snap.control(params["primitive"], action)

    return handler


def _routes() -> list[Route]:
    r = text_route
    return [
        # motors
        r("/motors/alias", lambda s, p: s.aliases()),
        r("/motors/get/positions", lambda s, p: s.positions()),
        r("/motors/set/registers/{settings}", lambda s, p: s.write_many(p["settings"])),
        r("/motors/set/goto/{settings}", lambda s, p: s.goto_many(p["settings"])),
        r("/motors/set/positions/{positions}", lambda s, p: s.set_positions(p["positions"])),
        r("/motors/{motors}/get/{register}", lambda s, p: s.read_many(p["motors"], p["register"])),
        r("/motors/{alias}", lambda s, p: s.motors_of(p["alias"])),
        r("/motor/{motor}/get/{register}", lambda s, p: s.read(p["motor"], p["register"])),
        r(
            "/motor/{motor}/set/{register}/{value}",
            lambda s, p: s.write(p["motor"], p["register"], p["value"]),
        ),
        r(
            "/motor/{motor}/goto/{position}/{duration}",
            lambda s, p: s.goto(p["motor"], p["position"], p["duration"]),
        ),
        # moves (before the generic primitive routes: a move may be called "get")
        r("/primitive/MoveRecorder", lambda s, p: s.moves()),
        r("/primitive/MovePlayer", lambda s, p: s.moves()),
        r("/primitive/MoveRecorder/{move}/start", lambda s, p: s.record(p["move"])),
        r(
            "/primitive/MoveRecorder/{move}/start/{motors}",
            lambda s, p: s.record(p["move"], p["motors"]),
        ),
        r(
            "/primitive/MoveRecorder/{move}/attach/{motors}",
            lambda s, p: s.attach(p["move"], p["motors"]),
        ),
        r("/primitive/MoveRecorder/{move}/get_motors", lambda s, p: s.recorded_motors(p["move"])),
        r("/primitive/MoveRecorder/{move}/stop", lambda s, p: s.save(p["move"]), blocking=True),
        r("/primitive/MoveRecorder/{move}/remove", lambda s, p: s.remove(p["move"]), blocking=True),
        r("/primitive/MovePlayer/{move}/start", lambda s, p: s.play(p["move"]), blocking=True),
        r(
            "/primitive/MovePlayer/{move}/start/{speed}",
            lambda s, p: s.play(p["move"], p["speed"]),
            blocking=True,
        ),
        r(
            "/primitive/MovePlayer/{move}/start/{speed}/backwards",
            lambda s, p: s.play(p["move"], p["speed"], backwards=True),
            blocking=True,
        ),
        r("/primitive/MovePlayer/{move}/stop", lambda s, p: s.stop_playing(p["move"])),
        # primitives
        r("/primitives", lambda s, p: s.primitives()),
        r("/primitives/running", lambda s, p: s.running()),
        *(
            r(f"/primitive/{{primitive}}/{action}", _control(action), blocking=True)
            for action in ("start", "stop", "pause", "resume")
        ),
        r("/primitive/{primitive}/properties", lambda s, p: s.properties(p["primitive"])),
        r("/primitive/{primitive}/methodes", lambda s, p: s.methods(p["primitive"])),
        r(
            "/primitive/{primitive}/get/{prop}",
            lambda s, p: s.get_property(p["primitive"], p["prop"]),
        ),
        r(
            "/primitive/{primitive}/set/{prop}/{value}",
            lambda s, p: s.set_property(p["primitive"], p["prop"], p["value"]),
        ),
        r(
            "/primitive/{primitive}/call/{method}",
            lambda s, p: s.call(p["primitive"], p["method"]),
            blocking=True,
        ),
        r(
            "/primitive/{primitive}/call/{method}/{args}",
            lambda s, p: s.call(p["primitive"], p["method"], p["args"]),
            blocking=True,
        ),
        # sensors, simulation, kinematics, address
        r("/detect/{marker}", lambda s, p: s.detect(p["marker"]), blocking=True),
        r("/reset-simulation", lambda s, p: s.reset_simulation(), blocking=True),
        r("/ik/{chain}/endeffector", lambda s, p: s.tip(p["chain"])),
        r(
            "/ik/{chain}/goto/{x}/{y}/{z}/{duration}",
            lambda s, p: s.ik_goto(p["chain"], (p["x"], p["y"], p["z"]), p["duration"]),
            blocking=True,
        ),
    ]


ROUTES = _routes()
"""The text routes (the site routes, blocks, projects, frame and address, are added by the app)."""


def route_paths() -> list[str]:
    """Every route path this server answers (for the generated blocks' checks and the docs)."""
    return [route.path for route in ROUTES] + list(SITE_PATHS)


SITE_PATHS = ("/", "/ip/", "/ip/{host}", "/frame.png", "/snap-blocks.xml", "/snap/{project}")


def create_snap_app(
    service: RobotService, site: SnapSite, *, snap_dir: Path | None = None
) -> Starlette:
    """The Snap! app over ``service`` (which the caller keeps and closes).

    Args:
        service: the robot's service (shared with the HTTP server when both run).
        site: the blocks and projects generated for this robot, and the server's address.
        snap_dir: a local copy of Snap! to serve under ``/app/`` (its ``snap.html``).
    """
    snap = SnapRobot(service)

    async def sitemap(request: Request) -> Response:
        lines = ["poppy's Snap! server: the routes (GET, plain-text answers)", *route_paths()]
        return PlainTextResponse("\n".join(lines), media_type=TEXT)

    async def ip(request: Request) -> Response:
        return PlainTextResponse(site.address(request.scope.get("server")), media_type=TEXT)

    async def frame(request: Request) -> Response:
        try:
            data = await run_in_threadpool(snap.frame_png)
        except (ApiError, PoppyError) as exc:
            status, line = error_text(exc)
            return PlainTextResponse(line, status_code=status, media_type=TEXT)
        return Response(data, media_type="image/png")

    async def blocks(request: Request) -> Response:
        return Response(site.blocks(request.headers.get("host")), media_type=XML)

    async def project(request: Request) -> Response:
        name = request.path_params["project"].removesuffix(".xml")
        body = site.project(name, request.headers.get("host"))
        if body is None:
            known = ", ".join(site.project_names())
            line = f"Error: no Snap! project {name[:60]!r} (projects: {known})"
            return PlainTextResponse(line, status_code=404, media_type=TEXT)
        return Response(body, media_type=XML)

    routes: list[Any] = [
        Route("/", sitemap, methods=["GET"]),
        Route("/ip/", ip, methods=["GET"]),
        Route("/ip/{host}", ip, methods=["GET"]),
        Route("/frame.png", frame, methods=["GET"]),
        Route("/snap-blocks.xml", blocks, methods=["GET"]),
        Route("/snap/{project}", project, methods=["GET"]),
        *ROUTES,
    ]
    if snap_dir is not None:
        routes.append(Mount(APP_PREFIX, StaticFiles(directory=snap_dir, html=True)))

    async def not_found(request: Request, exc: Exception) -> Response:
        line = f"Error: no Snap! route {request.url.path[:80]!r} (GET / lists the routes)"
        return PlainTextResponse(line, status_code=404, media_type=TEXT)

    async def bug(request: Request, exc: Exception) -> Response:
        line = f"Error: internal error ({type(exc).__name__}): the server's log has the details"
        return PlainTextResponse(line, status_code=500, media_type=TEXT)

    app = Starlette(routes=routes, exception_handlers={404: not_found, 405: not_found, 500: bug})
    app.state.snap = snap
    app.state.site = site
    return app
