"""pypot's answers: JSON typed ``text/html; charset=UTF-8`` and uncached, as pypot sent it.

pypot's HTTP server (pypot 5.0.2, ``pypot/server/httpserver.py``) wrote every answer as a JSON
*string* through Tornado, whose default type is then ``text/html; charset=UTF-8``, and set
``Cache-control: no-store`` on each. Pages written for it (puppet-master's move recorder) call
``JSON.parse`` on what jQuery hands them: jQuery parses a body itself only when it is typed as
JSON, so under ``application/json`` they parse an object again and throw. pypot's routes answer
the same way here; the v1 API stays ``application/json``.

A body typed HTML must never render as HTML if opened as a page: ``<``, ``>`` and ``&`` (which
JSON only holds inside strings) are sent as ``\\u003c``, ``\\u003e`` and ``\\u0026``, which
every JSON parser reads back as the same characters, and the page is sandboxed with no sources.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from typing import Any

from starlette.background import BackgroundTask
from starlette.responses import JSONResponse

PYPOT_CONTENT_TYPE = "text/html; charset=UTF-8"
PYPOT_HEADERS: dict[str, str] = {
    "X-Content-Type-Options": "nosniff",
    "Content-Security-Policy": "default-src 'none'; sandbox",
}
"""Sent with every answer of pypot's routes (besides the content type); pypot's
``Cache-control: no-store`` is added to every answer by ``origin_guard.OriginGuard``."""


ENCODER = json.JSONEncoder(ensure_ascii=False, allow_nan=False, separators=(",", ":"))
"""Starlette's JSON encoding (one encoder: ``json.dumps`` with options builds one per call)."""


def html_safe(body: bytes) -> bytes:
    """JSON ``body`` with ``<``, ``>`` and ``&`` escaped (same JSON, no markup)."""
    return body.replace(b"<", b"\\u003c").replace(b">", b"\\u003e").replace(b"&", b"\\u0026")


def pypot_bytes(content: Any) -> bytes:
    """``content`` encoded as a pypot route answers it (JSON, markup characters escaped).

    Raises:
        ValueError: ``content`` holds a non-finite number (not JSON).
    """
    return html_safe(ENCODER.encode(content).encode("utf-8"))


RAW_HEADERS: tuple[tuple[bytes, bytes], ...] = (
    (b"content-type", PYPOT_CONTENT_TYPE.encode()),
    *((name.lower().encode(), value.encode()) for name, value in PYPOT_HEADERS.items()),
)
"""The ASGI headers of every pypot answer but its length, encoded once (not per request)."""


def pypot_raw_headers(length: int) -> list[tuple[bytes, bytes]]:
    """The ASGI headers of a pypot answer of ``length`` bytes (for the fast path)."""
    return [*RAW_HEADERS, (b"content-length", b"%d" % length)]


class PypotJSON(JSONResponse):
    """A JSON answer of one of pypot's routes: pypot's content type and headers."""

    media_type = PYPOT_CONTENT_TYPE

    def __init__(
        self,
        content: Any,
        status_code: int = 200,
        headers: Mapping[str, str] | None = None,
        media_type: str | None = None,
        background: BackgroundTask | None = None,
    ) -> None:
        super().__init__(
            content, status_code, {**PYPOT_HEADERS, **(headers or {})}, media_type, background
        )

    def render(self, content: Any) -> bytes:
        return pypot_bytes(content)
