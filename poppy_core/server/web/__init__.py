"""The robot's home page at ``/``: static assets, its routes, the log buffer; ``add_web_page``."""

from __future__ import annotations

import base64
import hashlib
import re
import time
from importlib.resources import files
from typing import TYPE_CHECKING

from poppy_core.server.web.about_parts import NOTEBOOK_PORT
from poppy_core.server.web.logs import LogBuffer

if TYPE_CHECKING:
    from fastapi import FastAPI

STATIC_PREFIX = "/web/"
"""Where the page's assets are served (public: they hold no robot data)."""


def _import_map_hash() -> str:
    """The CSP source of index.html's import map (the 3D view's vendored three.js modules)."""
    page = (files("poppy_core.server.web") / "static" / "index.html").read_text("utf-8")
    found = re.search(r'<script type="importmap">(.*?)</script>', page, re.S)
    if found is None:
        return ""
    digest = base64.b64encode(hashlib.sha256(found.group(1).encode()).digest()).decode()
    return f" 'sha256-{digest}'"


PAGE_HEADERS = {
    # its own files only; no other site may frame it (a framed Stop or slider could be clicked
    # through a decoy page); the one inline script is the import map, allowed by its hash
    "Content-Security-Policy": (
        f"default-src 'self'; script-src 'self'{_import_map_hash()}; "
        "img-src 'self' blob: data:; media-src 'self' blob:; connect-src 'self'; "
        "frame-ancestors 'none'; base-uri 'none'; form-action 'self'"
    ),
    "X-Frame-Options": "DENY",
    "Referrer-Policy": "no-referrer",
}
PUBLIC_PATHS = ("/", "/favicon.ico")
"""Paths served without the token: the page must load to ask for it."""


def static_folder() -> str:
    """The folder of the page's assets (shipped in the wheel as package data)."""
    return str(files("poppy_core.server.web") / "static")


def add_web_page(app: FastAPI) -> None:
    """Serve the page at ``/``, its assets at ``/web/``, and its routes at ``/api/v1/web``.

    Other parts of the server add links to the page with ``add_link(app, name, url)``.
    """
    from starlette.responses import FileResponse, Response
    from starlette.staticfiles import StaticFiles

    from poppy_core.server.web.datasets import router as datasets_router
    from poppy_core.server.web.robot_model import router as model_router
    from poppy_core.server.web.routes import router

    app.state.web_started = time.monotonic()
    app.state.web_links = {"API docs": "/docs", "routes": "/routes"}
    app.state.web_notes = {}
    app.state.web_notebook_port = NOTEBOOK_PORT  # the Jupyter linked when it answers there
    app.state.web_notebook_seen = {}
    app.state.web_logs = LogBuffer()
    index = f"{static_folder()}/index.html"

    async def page() -> Response:
        return FileResponse(index, headers={"Cache-Control": "no-cache", **PAGE_HEADERS})

    async def favicon() -> Response:
        return FileResponse(f"{static_folder()}/favicon.svg", media_type="image/svg+xml")

    app.add_api_route("/", page, include_in_schema=False, methods=["GET"])
    app.add_api_route("/favicon.ico", favicon, include_in_schema=False, methods=["GET"])
    app.mount(STATIC_PREFIX, StaticFiles(directory=static_folder()), name="web")
    app.include_router(router, prefix="/api/v1")
    app.include_router(model_router, prefix="/api/v1")  # the 3D view's URDF and meshes
    app.include_router(datasets_router, prefix="/api/v1")  # the episodes' player (read only)


def add_link(app: FastAPI, name: str, url: str) -> None:
    """Show a link on the page (``poppy serve --snap`` adds Snap!'s, for example)."""
    app.state.web_links[name] = url


def add_note(app: FastAPI, name: str, text: str) -> None:
    """Show a line beside the links (how to get Snap! offline, for example)."""
    app.state.web_notes[name] = text


def is_public(path: str) -> bool:
    """True for the page and its assets, which need no token."""
    return path in PUBLIC_PATHS or path.startswith(STATIC_PREFIX)


__all__ = ["LogBuffer", "add_link", "add_note", "add_web_page", "is_public", "static_folder"]
