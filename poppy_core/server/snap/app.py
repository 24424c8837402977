"""``create_snap_app``: pypot's Snap! routes answering plain text, and the Snap! documents.

Every route is a GET (Snap!'s ``reportURL``). The text routes (``routes.py``) are dispatched by
``TextRouter``; the documents, the camera frame, the address and a local Snap! are Starlette
routes behind it. Reads of cached values and writes that only mark a
register answer from the event loop; what waits (stopping a primitive joins its thread, saving a
move writes a file, a camera frame, an IK solve) runs in the thread pool. Where pypot answers
500 (unknown motor, group, primitive, move or chain; a value that does not parse), this app
answers 404 or 400 with one line of text that a Snap! block can show.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from starlette.applications import Starlette
from starlette.concurrency import run_in_threadpool
from starlette.requests import Request
from starlette.responses import PlainTextResponse, Response
from starlette.routing import Mount, Route
from starlette.staticfiles import StaticFiles
from starlette.types import ASGIApp, Receive, Scope, Send

from poppy_core.errors import PoppyError
from poppy_core.server.errors import ApiError
from poppy_core.server.middleware import TokenMiddleware, request_token
from poppy_core.server.service import RobotService
from poppy_core.server.snap.routes import ROUTES
from poppy_core.server.snap.routing import TEXT, TextRouter, error_text
from poppy_core.server.snap.site import SnapSite
from poppy_core.server.snap.snap_robot import SnapRobot

XML = "application/xml; charset=utf-8"
APP_PREFIX = "/app"
"""Where a local Snap! copy (``--snap-dir``) is served."""


def route_paths() -> list[str]:
    """Every route path this server answers (the site's first, as ``/`` lists them)."""
    return list(SITE_PATHS) + [route.path for route in ROUTES]


SITE_PATHS = ("/", "/ip/", "/ip/{host}", "/frame.png", "/snap-blocks.xml", "/snap/{project}")


def _token(request: Request) -> str:
    """The token the request carried: a server with ``--token`` only answers ones that did."""
    if not request.app.state.token_required:
        return ""
    return request_token(request.scope) or ""


def create_snap_app(
    service: RobotService,
    site: SnapSite,
    *,
    snap_dir: Path | None = None,
    token: str | None = None,
) -> ASGIApp:
    """The Snap! app over ``service`` (which the caller keeps and closes): text routes, then site.

    Args:
        service: the robot's service (shared with the HTTP server when both run).
        site: the blocks and projects generated for this robot, and the server's address.
        snap_dir: a local copy of Snap! to serve under ``/app/`` (its ``snap.html``).
        token: when set, every route but the local Snap!'s files needs it (Bearer header or
            ``?token=``); the documents then carry it in every block's URL.
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
        body = site.blocks(request.headers.get("host"), token=_token(request))
        return Response(body, media_type=XML)

    async def project(request: Request) -> Response:
        name = request.path_params["project"].removesuffix(".xml")
        body = site.project(name, request.headers.get("host"), _token(request))
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
    ]
    if snap_dir is not None:
        routes.append(Mount(APP_PREFIX, StaticFiles(directory=snap_dir, html=True)))

    async def not_found(request: Request, exc: Exception) -> Response:
        line = f"Error: no Snap! route {request.url.path[:80]!r} (GET / lists the routes)"
        return PlainTextResponse(line, status_code=404, media_type=TEXT)

    async def bug(request: Request, exc: Exception) -> Response:
        line = f"Error: internal error ({type(exc).__name__}): the server's log has the details"
        return PlainTextResponse(line, status_code=500, media_type=TEXT)

    site_app = Starlette(
        routes=routes, exception_handlers={404: not_found, 405: not_found, 500: bug}
    )
    site_app.state.snap = snap
    site_app.state.site = site
    site_app.state.token_required = bool(token)
    router = TextRouter(site_app, snap, ROUTES)
    if not token:
        return router
    guarded = TokenMiddleware(router, token)

    async def app(scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] == "http" and str(scope.get("path", "")).startswith(APP_PREFIX + "/"):
            await router(scope, receive, send)  # Snap!'s own files hold nothing of the robot
        else:
            await guarded(scope, receive, send)

    return app
