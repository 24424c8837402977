"""Answers that refuse a request before any route runs: one JSON line, for HTTP and WebSocket.

Every refusal has pypot's error shape plus the v1 ``detail`` key, so both kinds of clients show
it: ``{"error": what, "tip": how to do it right, "details": "", "detail": what}``.
"""

from __future__ import annotations

import json
from collections.abc import Sequence

from starlette.types import Scope, Send

MAX_MESSAGE_CHARS = 300
"""Longest error text sent back (a refused 4,000-digit number is not echoed whole)."""
MAX_CLOSE_REASON_BYTES = 123
"""Longest WebSocket close reason the protocol allows."""


def one_line(text: str, limit: int = MAX_MESSAGE_CHARS) -> str:
    """``text`` on one line and at most ``limit`` characters (an ellipsis marks a cut)."""
    flat = " ".join(text.split())
    return flat if len(flat) <= limit else flat[: limit - 1] + "…"


def refusal_body(message: str, tip: str = "", details: str = "") -> bytes:
    """The JSON body of a refusal."""
    line = one_line(message)
    body = {"error": line, "tip": one_line(tip), "details": one_line(details), "detail": line}
    return json.dumps(body).encode()


async def refuse(
    scope: Scope,
    send: Send,
    status: int,
    message: str,
    tip: str = "",
    headers: Sequence[tuple[bytes, bytes]] = (),
) -> None:
    """Answer ``status`` with a refusal body; a WebSocket handshake gets the same as its answer.

    Servers without the WebSocket denial-response extension close the handshake instead
    (code 1008, the message as reason; clients see an HTTP 403).
    """
    body = refusal_body(message, tip)
    start_headers = [
        (b"content-type", b"application/json"),
        (b"content-length", str(len(body)).encode()),
        *headers,
    ]
    if scope["type"] == "websocket":
        if "websocket.http.response" in scope.get("extensions", {}):
            start = {"type": "websocket.http.response.start", "status": status}
            await send({**start, "headers": start_headers})
            await send({"type": "websocket.http.response.body", "body": body})
        else:
            reason = one_line(message).encode()[:MAX_CLOSE_REASON_BYTES].decode(errors="ignore")
            await send({"type": "websocket.close", "code": 1008, "reason": reason})
        return
    await send({"type": "http.response.start", "status": status, "headers": start_headers})
    await send({"type": "http.response.body", "body": body})
