"""ASGI middleware: pypot's CORS headers and OPTIONS answers, the token, and a body size limit.

Written as plain ASGI callables (no ``BaseHTTPMiddleware``) so they cost little per request and
also guard WebSocket handshakes.
"""

from __future__ import annotations

import hmac
import json
from collections.abc import Sequence
from typing import Any
from urllib.parse import parse_qs

from starlette.types import ASGIApp, Message, Receive, Scope, Send

MAX_BODY_BYTES = 64 * 1024
"""Largest request body accepted (bytes)."""

ALLOW_HEADERS = b"Origin, Accept, Content-Type, X-Requested-With, X-CSRF-Token, Authorization"
ALLOW_METHODS = b"GET, POST, PUT, PATCH, DELETE, OPTIONS"


async def _send_json(send: Send, status: int, body: dict[str, Any], extra: list[Any]) -> None:
    payload = json.dumps(body).encode()
    headers = [
        (b"content-type", b"application/json"),
        (b"content-length", str(len(payload)).encode()),
        *extra,
    ]
    await send({"type": "http.response.start", "status": status, "headers": headers})
    await send({"type": "http.response.body", "body": payload})


class CorsMiddleware:
    """pypot's headers on every answer (no-store, CORS) and 204 to every OPTIONS request.

    Args:
        app: the wrapped app.
        origins: allowed origins; ``("*",)`` (pypot's default) allows any.
    """

    def __init__(self, app: ASGIApp, origins: Sequence[str] = ("*",)) -> None:
        self.app = app
        self.any_origin = "*" in origins
        self.origins = {o.encode() for o in origins}

    def headers_for(self, scope: Scope) -> list[tuple[bytes, bytes]]:
        """The headers added to an answer to ``scope``."""
        out = [(b"cache-control", b"no-store")]
        if self.any_origin:
            allowed = b"*"
        else:
            origin = dict(scope["headers"]).get(b"origin", b"")
            if origin not in self.origins:
                return out
            allowed = origin
            out.append((b"vary", b"Origin"))
        out += [
            (b"access-control-allow-origin", allowed),
            (b"access-control-allow-headers", ALLOW_HEADERS),
            (b"access-control-allow-methods", ALLOW_METHODS),
        ]
        return out

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        extra = self.headers_for(scope)
        if scope["method"] == "OPTIONS":
            await send({"type": "http.response.start", "status": 204, "headers": extra})
            await send({"type": "http.response.body", "body": b""})
            return

        async def send_with_headers(message: Message) -> None:
            if message["type"] == "http.response.start":
                message = {**message, "headers": [*message.get("headers", []), *extra]}
            await send(message)

        await self.app(scope, receive, send_with_headers)


def request_token(scope: Scope) -> str | None:
    """The token a request carries: ``Authorization: Bearer …`` or ``?token=…``."""
    for key, value in scope.get("headers", []):
        if key == b"authorization":
            scheme, _, token = bytes(value).decode("latin-1").partition(" ")
            if scheme.lower() == "bearer":
                return str(token).strip()
    query = scope.get("query_string", b"").decode("latin-1")
    if "token=" in query:
        tokens: list[str] = parse_qs(query).get("token", [])
        if tokens:
            return str(tokens[0])
    return None


class TokenMiddleware:
    """Refuse (401) every HTTP request and WebSocket handshake without the token.

    Args:
        app: the wrapped app.
        token: the secret.
    """

    def __init__(self, app: ASGIApp, token: str) -> None:
        self.app = app
        self.token = token.encode()

    def allowed(self, scope: Scope) -> bool:
        """True when ``scope`` carries the token."""
        given = request_token(scope)
        return given is not None and hmac.compare_digest(given.encode(), self.token)

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] not in ("http", "websocket") or self.allowed(scope):
            await self.app(scope, receive, send)
            return
        if scope["type"] == "websocket":
            await send({"type": "websocket.close", "code": 1008, "reason": "token required"})
            return
        body = {
            "error": "a token is required",
            "tip": "send the header 'Authorization: Bearer <token>' or add ?token=<token>",
            "details": "this server was started with --token",
            "detail": "a token is required",
        }
        await _send_json(send, 401, body, [(b"www-authenticate", b"Bearer")])


class BodyLimitMiddleware:
    """Refuse (413) request bodies larger than ``max_bytes`` before any route reads them.

    Args:
        app: the wrapped app.
        max_bytes: the limit.
    """

    def __init__(self, app: ASGIApp, max_bytes: int = MAX_BODY_BYTES) -> None:
        self.app = app
        self.max_bytes = max_bytes

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http" or scope["method"] in ("GET", "HEAD", "OPTIONS"):
            await self.app(scope, receive, send)
            return
        length = dict(scope["headers"]).get(b"content-length")
        if length is not None and length.isdigit() and int(length) > self.max_bytes:
            await self._refuse(send)
            return
        chunks: list[bytes] = []
        size = 0
        more = True
        while more:
            message = await receive()
            if message["type"] != "http.request":
                await self.app(scope, receive, send)
                return
            chunk = message.get("body", b"")
            size += len(chunk)
            if size > self.max_bytes:
                await self._refuse(send)
                return
            chunks.append(chunk)
            more = message.get("more_body", False)
        body = b"".join(chunks)
        replayed = False

        async def replay() -> Message:
            nonlocal replayed
            if not replayed:
                replayed = True
                return {"type": "http.request", "body": body, "more_body": False}
            return await receive()

        await self.app(scope, replay, send)

    async def _refuse(self, send: Send) -> None:
        message = f"the request body is larger than {self.max_bytes} bytes"
        body = {"error": message, "tip": "send a smaller body", "details": "", "detail": message}
        await _send_json(send, 413, body, [(b"connection", b"close")])
