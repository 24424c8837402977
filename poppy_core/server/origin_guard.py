"""The ASGI guard applying an ``OriginPolicy``: foreign Host names (400) and origins (403)
refused before the app runs, preflights answered, CORS and ``no-store`` headers added."""

from __future__ import annotations

from collections.abc import Callable

from starlette.types import ASGIApp, Message, Receive, Scope, Send

from poppy_core.server.origins import OriginPolicy, Verdict
from poppy_core.server.refusals import refuse

SAFE_METHODS = frozenset({"GET", "HEAD", "OPTIONS"})
ALLOW_HEADERS = b"Origin, Accept, Content-Type, X-Requested-With, X-CSRF-Token, Authorization"
ALLOW_METHODS = b"GET, POST, PUT, PATCH, DELETE, OPTIONS"
PREFLIGHT_MAX_AGE = b"600"
NO_STORE = (b"cache-control", b"no-store")
PYPOT_OPEN_HEADERS = [
    NO_STORE,
    (b"access-control-allow-origin", b"*"),
    (b"access-control-allow-headers", ALLOW_HEADERS),
    (b"access-control-allow-methods", ALLOW_METHODS),
]
"""pypot's headers on every answer, kept for ``--cors '*'``."""
CROSS_SITE = (b"cross-site", b"same-site")


def default_changes_state(scope: Scope) -> bool:
    """True for what may change the robot: a WebSocket, any method but GET/HEAD/OPTIONS.

    An app with GET routes that change the robot passes its own rule, decided on the route a
    request reaches (the REST app: ``state_routes.changes_state_as_routed``).
    """
    return scope["type"] == "websocket" or scope["method"] not in SAFE_METHODS


class OriginGuard:
    """Apply an ``OriginPolicy`` to every HTTP request and WebSocket handshake of ``app``.

    Refuses foreign Host names (400) and origins (403) before the app sees them, answers
    ``OPTIONS`` preflights (204), and adds ``Cache-Control: no-store`` and, for allowed foreign
    origins, the CORS headers to every answer.

    Args:
        app: the wrapped app.
        policy: the rules (shared by the servers of one ``poppy serve``).
        changes_state: which requests may change the robot (cross-site ones without ``Origin``
            are refused); every WebSocket and non-GET request by default.
    """

    def __init__(
        self,
        app: ASGIApp,
        policy: OriginPolicy,
        changes_state: Callable[[Scope], bool] = default_changes_state,
    ) -> None:
        self.app = app
        self.policy = policy
        self.changes_state = changes_state

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] not in ("http", "websocket"):
            await self.app(scope, receive, send)
            return
        host = origin = fetch_site = None
        repeated = False
        for name, value in scope["headers"]:
            if name == b"host":
                repeated = repeated or host is not None
                host = value
            elif name == b"origin":
                repeated = repeated or origin is not None
                origin = value
            elif name == b"sec-fetch-site":
                fetch_site = value
        policy = self.policy
        if repeated or not policy.host_allowed(host):
            text = (host or b"").decode("latin-1")
            message = policy.refused_host(text) if not repeated else "repeated Host or Origin"
            tip = "open the robot by its address or a name the server allows"
            await refuse(scope, send, 400, message, tip)
            return
        allow: bytes | None = b"*" if policy.any_origin else None
        if origin is not None:
            server = scope.get("server")
            verdict = policy.verdict(origin, host, server[1] if server else None)
            if verdict is Verdict.FOREIGN:
                message = policy.refused_origin(origin.decode("latin-1"))
                await refuse(scope, send, 403, message, "the server's operator can allow it")
                return
            if verdict in (Verdict.ALLOWED, Verdict.SIBLING) and allow is None:
                allow = origin
        elif fetch_site in CROSS_SITE and not policy.any_origin and self.changes_state(scope):
            message = policy.refused_cross_site()
            await refuse(scope, send, 403, message, "use fetch() from an allowed origin")
            return
        if scope["type"] == "websocket":
            await self.app(scope, receive, send)
            return
        if allow is None:
            extra = [NO_STORE]
        elif allow == b"*":
            extra = PYPOT_OPEN_HEADERS
        else:
            extra = [NO_STORE, (b"access-control-allow-origin", allow), (b"vary", b"Origin")]
        if scope["method"] == "OPTIONS":
            await self._preflight(scope, send, extra, allow is not None)
            return

        async def send_with_headers(message: Message) -> None:
            if message["type"] == "http.response.start":
                message = {**message, "headers": [*message.get("headers", []), *extra]}
            await send(message)

        await self.app(scope, receive, send_with_headers)

    @staticmethod
    async def _preflight(
        scope: Scope, send: Send, extra: list[tuple[bytes, bytes]], cors: bool
    ) -> None:
        listed = (b"access-control-allow-headers", b"access-control-allow-methods")
        headers = [h for h in extra if h[0] not in listed]
        if cors:
            headers += [
                (b"access-control-allow-headers", ALLOW_HEADERS),
                (b"access-control-allow-methods", ALLOW_METHODS),
                (b"access-control-max-age", PREFLIGHT_MAX_AGE),
            ]
            if (b"access-control-request-private-network", b"true") in scope["headers"]:
                # Chrome asks before a public page reaches a loopback server (Private Network
                # Access): the origin is allowed, so is this.
                headers.append((b"access-control-allow-private-network", b"true"))
        await send({"type": "http.response.start", "status": 204, "headers": headers})
        await send({"type": "http.response.body", "body": b""})
