"""Untrusted JSON in: bodies and WebSocket messages parsed into data or one ``ApiError`` line.

The parsing is ``poppy_core.documents.parse_json`` (the one JSON reader of the house): bad
syntax, nesting deeper than the interpreter's recursion or than ``REQUEST_LIMITS``, an integer of
more than 4,300 digits are all a client's mistake (4xx), never a server error.
"""

from __future__ import annotations

from typing import Any

from poppy_core.documents import REQUEST_LIMITS
from poppy_core.documents import parse_json as parse_document
from poppy_core.errors import ConfigError
from poppy_core.server.errors import ApiError


def parse_json(raw: bytes | str, *, what: str = "the body", tip: str = "") -> Any:
    """``raw`` parsed as JSON; ``what`` names it in errors (``"the body"``, ``"the message"``).

    Raises:
        ApiError: ``"invalid"``, with one line saying what is wrong.
    """
    try:
        return parse_document(raw, what, REQUEST_LIMITS)
    except ConfigError as exc:
        raise ApiError("invalid", str(exc), tip=tip) from None
