"""Which requests may change the robot, decided on the route a request reaches, not its spelling.

The Origin guard refuses a cross-site request without ``Origin`` (a link or an ``<img>`` on any
web page) when it may change the robot. Every non-GET request and WebSocket may; among the GET
routes, those marked ``CHANGES_STATE`` (pypot's primitive controls) do. The guard runs before
``LegacyPaths`` rewrites pypot's old spellings (``/primitive/sinus/start.json``) and before the
router redirects a trailing slash, so the path is resolved here the way the app will route it,
and matched against the marked routes themselves: a route added with the mark is covered in
every spelling without a list to keep.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

from starlette.types import Scope

from poppy_core.server.legacy_paths import current_path
from poppy_core.server.origin_guard import SAFE_METHODS
from poppy_core.server.routers.common import CHANGES_STATE

if TYPE_CHECKING:
    import re

    from fastapi import FastAPI

MARK = next(iter(CHANGES_STATE))


def marked_routes(app: FastAPI) -> list[tuple[str, re.Pattern[str]]]:
    """The GET routes of ``app`` marked as changing the robot: (path template, its regex).

    Read from the app's OpenAPI document, where the mark shows (a marked route is in it).
    """
    from starlette.routing import compile_path

    return [
        (path, compile_path(path)[0])
        for path, operations in app.openapi().get("paths", {}).items()
        if any(isinstance(op, dict) and op.get(MARK) for op in operations.values())
    ]


def routed_paths(path: str) -> set[str]:
    """The paths the app may route ``path`` to: itself, its current spelling, without a slash."""
    candidates = {path}
    if path.endswith("/") and path != "/":  # the router redirects it to the path without
        candidates.add(path.rstrip("/") or "/")
    return candidates | {p for p in map(current_path, candidates) if p is not None}


def changes_state_as_routed(app: FastAPI) -> Callable[[Scope], bool]:
    """The guard's ``changes_state`` for ``app``: True for a request reaching a marked route."""
    routes: list[tuple[str, re.Pattern[str]]] | None = None

    def changes_state(scope: Scope) -> bool:
        nonlocal routes
        if scope["type"] == "websocket" or scope["method"] not in SAFE_METHODS:
            return True
        if routes is None:  # the routes are all added once the first request comes
            routes = marked_routes(app)
        paths = routed_paths(str(scope["path"]))
        return any(regex.match(path) for _, regex in routes for path in paths)

    return changes_state
