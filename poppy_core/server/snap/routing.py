"""Plain-text routes dispatched without a framework: the hot path of the Snap! server.

Snap! polls positions and sends gotos many times a second; matching a path against the
templates segment by segment and answering with two ASGI messages costs a fraction of a
framework's request and response objects. What is not a text route (documents, the frame, a
local Snap!) goes on to the wrapped app.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

from starlette.concurrency import run_in_threadpool
from starlette.types import ASGIApp, Receive, Scope, Send

from poppy_core.errors import PoppyError
from poppy_core.server.errors import PYPOT_STATUS, ApiError, from_poppy_error
from poppy_core.server.refusals import one_line
from poppy_core.server.snap.snap_robot import SnapRobot

logger = logging.getLogger(__name__)

TEXT = "text/plain; charset=utf-8"
Handler = Callable[[SnapRobot, dict[str, str]], str]


def error_text(exc: Exception) -> tuple[int, str]:
    """Status and one line for a refusal (``Error: ...``, as pypot's blocks show errors)."""
    error = from_poppy_error(exc) if isinstance(exc, PoppyError) else exc
    assert isinstance(error, ApiError)
    status = PYPOT_STATUS[error.kind] if error.kind != "conflict" else 409
    message = one_line(error.message)
    return status, message if message.startswith("Error") else f"Error: {message}"


@dataclass(frozen=True)
class TextRoute:
    """A GET route answering ``handler(snap, params)`` as text.

    Args:
        path: the template, ``{name}`` for a parameter (one path segment).
        handler: what it does.
        blocking: run the handler in the thread pool (it waits: a join, a file, a solve).
    """

    path: str
    handler: Handler
    blocking: bool = False
    parts: tuple[str | None, ...] = field(init=False)
    names: tuple[str, ...] = field(init=False)

    def __post_init__(self) -> None:
        segments = self.path.split("/")[1:]
        parts = tuple(None if s.startswith("{") else s for s in segments)
        names = tuple(s[1:-1] for s in segments if s.startswith("{"))
        object.__setattr__(self, "parts", parts)
        object.__setattr__(self, "names", names)

    def match(self, segments: Sequence[str]) -> dict[str, str] | None:
        """The parameters when ``segments`` (a path split at ``/``) fit the template."""
        if len(segments) != len(self.parts):
            return None
        values = []
        for part, segment in zip(self.parts, segments, strict=True):
            if part is None:
                if not segment:
                    return None
                values.append(segment)
            elif part != segment:
                return None
        return dict(zip(self.names, values, strict=True))


class TextRouter:
    """ASGI: answer the text routes of ``routes`` for ``snap``; pass anything else to ``app``."""

    def __init__(self, app: ASGIApp, snap: SnapRobot, routes: Sequence[TextRoute]) -> None:
        self.app = app
        self.snap = snap
        self.by_length: dict[int, list[TextRoute]] = {}
        for route in routes:
            self.by_length.setdefault(len(route.parts), []).append(route)

    def match(self, path: str) -> tuple[TextRoute, dict[str, str]] | None:
        """The route ``path`` reaches and its parameters, or None."""
        segments = path.split("/")[1:]
        for route in self.by_length.get(len(segments), ()):
            params = route.match(segments)
            if params is not None:
                return route, params
        return None

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        found = None
        if scope["type"] == "http" and scope["method"] in ("GET", "HEAD"):
            found = self.match(scope["path"])
        if found is None:
            await self.app(scope, receive, send)
            return
        route, params = found
        status = 200
        try:
            if route.blocking:
                text = await run_in_threadpool(route.handler, self.snap, params)
            else:
                text = route.handler(self.snap, params)
        except (ApiError, PoppyError) as exc:
            status, text = error_text(exc)
            logger.info("GET %s refused: %s", scope["path"], text)
        body = text.encode()
        headers = [(b"content-type", TEXT.encode()), (b"content-length", str(len(body)).encode())]
        await send({"type": "http.response.start", "status": status, "headers": headers})
        await send(
            {"type": "http.response.body", "body": b"" if scope["method"] == "HEAD" else body}
        )
