"""ASGI middleware: the token and a body size limit (the Host/Origin rules are in ``origins``).

Written as plain ASGI callables (no ``BaseHTTPMiddleware``) so they cost little per request and
also guard WebSocket handshakes.
"""

from __future__ import annotations

import hmac
from collections.abc import Callable
from urllib.parse import parse_qs

from starlette.types import ASGIApp, Message, Receive, Scope, Send

from poppy_core.server.refusals import refuse

MAX_BODY_BYTES = 64 * 1024
"""Largest request body accepted (bytes)."""


TOKEN_PROTOCOL = "poppy-token."
"""A WebSocket subprotocol ``poppy-token.<token in hex>`` carries the token: browsers cannot
give a WebSocket a header, and a subprotocol keeps it out of the URL (the web page uses it)."""


def protocol_token(scope: Scope) -> str | None:
    """The token of a ``poppy-token.<hex>`` WebSocket subprotocol, if one was offered."""
    for protocol in scope.get("subprotocols", []):
        if isinstance(protocol, str) and protocol.startswith(TOKEN_PROTOCOL):
            try:
                return bytes.fromhex(protocol[len(TOKEN_PROTOCOL) :]).decode("utf-8")
            except ValueError:
                return None
    return None


def token_protocol(scope: Scope) -> str | None:
    """The ``poppy-token.`` subprotocol a WebSocket client offered (the server accepts it)."""
    for protocol in scope.get("subprotocols", []):
        if isinstance(protocol, str) and protocol.startswith(TOKEN_PROTOCOL):
            return protocol
    return None


def request_token_bytes(scope: Scope) -> bytes | None:
    """The token a request carries, as the bytes it carries them: ``Authorization: Bearer …``,
    ``?token=…`` (percent-decoded), or (WebSocket) a ``poppy-token.<hex>`` subprotocol.

    Bytes, never text decoded one way and encoded another: a header is read as Latin-1 by
    ASGI servers, so a non-ASCII token sent in UTF-8 never matched once re-encoded.
    """
    if scope["type"] == "websocket":
        token = protocol_token(scope)
        if token is not None:
            return token.encode()
    for key, value in scope.get("headers", []):
        if key == b"authorization":
            scheme, _, raw = bytes(value).partition(b" ")
            if scheme.lower() == b"bearer":
                return raw.strip()
    query = bytes(scope.get("query_string", b"")).decode("latin-1")  # one char per byte
    if "token=" in query:
        tokens: list[str] = parse_qs(query, encoding="latin-1").get("token", [])
        if tokens:
            return tokens[0].encode("latin-1")
    return None


def request_token(scope: Scope) -> str | None:
    """The token a request carries as text (UTF-8), to be written in the documents it gets."""
    raw = request_token_bytes(scope)
    return None if raw is None else raw.decode("utf-8", errors="replace")


class TokenMiddleware:
    """Refuse (401) every HTTP request and WebSocket handshake without the token.

    Args:
        app: the wrapped app.
        token: the secret.
        public: paths served without the token (GET only: the web page and its assets, which
            must load to ask for the token and hold no robot data).
    """

    def __init__(
        self, app: ASGIApp, token: str, public: Callable[[str], bool] | None = None
    ) -> None:
        self.app = app
        self.token = token.encode()
        self.public = public

    def allowed(self, scope: Scope) -> bool:
        """True when ``scope`` carries the token."""
        given = request_token_bytes(scope)
        return given is not None and hmac.compare_digest(given, self.token)

    def _public(self, scope: Scope) -> bool:
        return (
            self.public is not None
            and scope["type"] == "http"
            and scope["method"] in ("GET", "HEAD")
            and self.public(scope["path"])
        )

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] not in ("http", "websocket") or self._public(scope) or self.allowed(scope):
            await self.app(scope, receive, send)
            return
        await refuse(
            scope,
            send,
            401,
            "a token is required (this server was started with --token)",
            "send the header 'Authorization: Bearer <token>' or add ?token=<token>",
            [(b"www-authenticate", b"Bearer")],
        )


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
            await self._refuse(scope, send)
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
                await self._refuse(scope, send)
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

    async def _refuse(self, scope: Scope, send: Send) -> None:
        message = f"the request body is larger than {self.max_bytes} bytes"
        await refuse(scope, send, 413, message, "send a smaller body", [(b"connection", b"close")])
