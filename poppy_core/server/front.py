"""``GuardedAPI``: a FastAPI app whose guards run in front of FastAPI's own layers.

FastAPI places the middleware an app adds inside three layers of its own (its 500 handler, its
telemetry, its body limit: about ten Python calls a request). The REST app's guards (Host and
Origin, the token, the body size) and pypot's fast path need none of them: every request and
WebSocket handshake meets the guards first, and only what the fast path does not answer goes on
through FastAPI. Every check stays; the fast path hands anything unusual, a failure included, to
the routes, whose handlers answer it (a 500 with one line for a failure).
"""

from __future__ import annotations

from collections.abc import Callable

from fastapi import FastAPI  # noqa: TID253 (the server room is FastAPI's; imported by create_app)
from starlette.types import ASGIApp, Receive, Scope, Send


class GuardedAPI(FastAPI):
    """A FastAPI app served through ``front`` (built by ``guard``) for HTTP and WebSocket."""

    front: ASGIApp | None = None

    def guard(self, *layers: Callable[[ASGIApp], ASGIApp]) -> None:
        """Put ``layers`` in front of the app, the first outermost (each wraps the next)."""
        app: ASGIApp = self.behind_guards
        for layer in reversed(layers):
            app = layer(app)
        self.front = app

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        front = self.front
        if front is None or scope["type"] == "lifespan":
            await super().__call__(scope, receive, send)
            return
        await front(scope, receive, send)

    async def behind_guards(self, scope: Scope, receive: Receive, send: Send) -> None:
        """FastAPI's own app (its layers, the routes), reached once the guards let through."""
        await super().__call__(scope, receive, send)
