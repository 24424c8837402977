"""``create_teacher_app(fleet)``: the teacher's page and its API, with a robot page's rules (the
token, the Host and Origin checks, the body limit, the page's security headers and look);
``TeacherServer`` serves it in a thread over a fleet of its own."""

from __future__ import annotations

import threading
from collections.abc import AsyncIterator, Callable
from contextlib import asynccontextmanager
from importlib.resources import files
from typing import TYPE_CHECKING, Any

from starlette.responses import FileResponse, Response
from starlette.staticfiles import StaticFiles

from poppy_core.server.errors import install_error_handlers
from poppy_core.server.middleware import BodyLimitMiddleware, TokenMiddleware
from poppy_core.server.origin_guard import OriginGuard
from poppy_core.server.origins import OriginPolicy
from poppy_core.server.runner import ServerThread, bind_sockets
from poppy_core.server.teacher import routes
from poppy_core.server.teacher.watch import FleetWatch
from poppy_core.server.web import PAGE_HEADERS, STATIC_PREFIX, static_folder

if TYPE_CHECKING:
    from fastapi import FastAPI

    from poppy_core.remote.zenoh_fleet import Fleet

TEACHER_PREFIX = "/teacher/"
"""Where the teacher's page's own assets are (the robot page's are at ``/web/``: its style, its
API calls with the token prompt)."""
PUBLIC_PATHS = ("/", "/favicon.ico")
LOOPBACK_HOSTS = frozenset({"127.0.0.1", "localhost", "::1"})


def teacher_folder() -> str:
    """The folder of the teacher's page's own assets (package data)."""
    return str(files("poppy_core.server.teacher") / "static")


def is_public(path: str) -> bool:
    """The page and its assets, which need no token (they hold no robot data)."""
    return path in PUBLIC_PATHS or path.startswith(STATIC_PREFIX) or path.startswith(TEACHER_PREFIX)


def create_teacher_app(
    fleet: Fleet, *, token: str | None = None, policy: OriginPolicy | None = None
) -> FastAPI:
    """The teacher's page over ``fleet`` (which the caller keeps and closes).

    Args:
        fleet: the robots' Zenoh fleet; with its own ``token`` it signs every command.
        token: when set, every route and the stream need it, as on a robot's page (Bearer
            header, ``?token=`` or the ``poppy-token.`` WebSocket subprotocol); the page and
            its assets load without it, to ask for it.
        policy: the Host names and origins accepted (default: loopback names, IP addresses
            and the page's own origin).
    """
    from fastapi import FastAPI

    from poppy_core.server.app import no_telemetry

    watch = FleetWatch(fleet)

    @asynccontextmanager
    async def lifespan(app: FastAPI) -> AsyncIterator[None]:
        watch.start()
        try:
            yield
        finally:
            watch.close()

    app = FastAPI(
        title="poppy fleet: the teacher's page",
        docs_url=None,
        lifespan=lifespan,
        **no_telemetry(FastAPI),
    )
    app.state.fleet = fleet
    app.state.watch = watch
    app.state.starts = threading.Lock()
    install_error_handlers(app)
    page_file = f"{teacher_folder()}/index.html"

    async def page() -> Response:
        return FileResponse(page_file, headers={"Cache-Control": "no-cache", **PAGE_HEADERS})

    async def favicon() -> Response:
        return FileResponse(f"{static_folder()}/favicon.svg", media_type="image/svg+xml")

    app.add_api_route("/", page, include_in_schema=False, methods=["GET"])
    app.add_api_route("/favicon.ico", favicon, include_in_schema=False, methods=["GET"])
    app.mount(STATIC_PREFIX, StaticFiles(directory=static_folder()), name="web")
    app.mount(TEACHER_PREFIX, StaticFiles(directory=teacher_folder()), name="teacher")
    app.include_router(routes.router, prefix="/api/v1")
    app.add_api_websocket_route("/api/v1/fleet/ws", routes.stream)
    app.add_middleware(BodyLimitMiddleware)
    if token:
        app.add_middleware(TokenMiddleware, token=token, public=is_public)
    app.add_middleware(OriginGuard, policy=policy or OriginPolicy())  # outermost
    return app


def exposure(host: str, token: str | None, cors: tuple[str, ...] = ()) -> list[str]:
    """What the page lets others do when it is reachable from the network or open to every web
    page: one line each (none on loopback for its own page)."""
    lines = []
    if host.strip("[]") not in LOOPBACK_HOSTS and not token:
        lines.append(
            f"serving the teacher's page on {host} without a token: anyone who can reach this "
            "machine can drive every robot of the fleet; give a token or keep 127.0.0.1"
        )
    if any(origin.strip() == "*" for origin in cors):
        lines.append(
            "cors '*': every web page you open can drive the fleet; allow the origins you use "
            "instead"
        )
    return lines


class TeacherServer:
    """The teacher's page served in a thread over a fleet it opens: ``start``, ``stop``.

    Args:
        open_fleet: opens the robots' fleet (``Fleet(settings, token=...)``: the token it signs
            the commands with); called once the port is bound, closed on ``stop``.
        host: address to listen on (loopback by default).
        port: HTTP port (0 picks a free one: read ``port`` once started).
        token: the page's token, which also signs every command to the robots.
        cors: foreign origins allowed (``"*"`` any).
        allow_hosts: Host names answered besides loopback names, IPs and ``host``.
        report: called with one line the first time an origin or Host name is refused.
    """

    def __init__(
        self,
        open_fleet: Callable[[], Fleet],
        *,
        host: str = "127.0.0.1",
        port: int = 0,
        token: str | None = None,
        cors: tuple[str, ...] = (),
        allow_hosts: tuple[str, ...] = (),
        report: Any = None,
    ) -> None:
        self.open_fleet = open_fleet
        self.host = host
        self.port = port
        self.token = token
        self.policy = OriginPolicy.for_server(
            host,
            cors=cors,
            allow_hosts=allow_hosts,
            origin_hint="restart poppy fleet serve with --cors {origin}",
            host_hint="restart poppy fleet serve with --allow-host {host}",
            report=report,
        )
        self.fleet: Fleet | None = None
        self.thread: ServerThread | None = None

    @property
    def url(self) -> str:
        """``http://host:port`` (the port known once started)."""
        host = f"[{self.host}]" if ":" in self.host else self.host
        return f"http://{host}:{self.port}"

    @property
    def running(self) -> bool:
        """True while the HTTP server's thread runs."""
        return self.thread is not None and self.thread.running

    def start(self) -> TeacherServer:
        """Bind the port (a busy one is a ``ListenError``), join Zenoh, then serve.

        Raises:
            ListenError: the address or port cannot be used.
            PoppyError: the fleet cannot be opened (Zenoh's settings refused, no router).
        """
        sockets = bind_sockets(self.host, self.port)  # a busy port is said before Zenoh waits
        try:
            self.port = int(sockets[0].getsockname()[1])
            self.fleet = self.open_fleet()
            app = create_teacher_app(self.fleet, token=self.token, policy=self.policy)
            self.thread = ServerThread(app, self.host, self.port, sockets=sockets).start()
        except BaseException:
            for sock in sockets:
                sock.close()
            self.stop()
            raise
        return self

    def stop(self) -> None:
        """Stop serving, then leave Zenoh."""
        if self.thread is not None:
            self.thread.stop()
            self.thread = None
        if self.fleet is not None:
            self.fleet.close()
            self.fleet = None

    def __enter__(self) -> TeacherServer:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()
