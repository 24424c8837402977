"""Untrusted JSON in: bodies and WebSocket messages parsed into data or one ``ApiError`` line.

``json.loads`` refuses more than bad syntax: nesting deeper than the interpreter's recursion
limit raises ``RecursionError`` and an integer of more than 4,300 digits a ``ValueError``. All of
them are a client's mistake (4xx), never a server error.
"""

from __future__ import annotations

import json
from typing import Any

from poppy_core.server.errors import ApiError


def parse_json(raw: bytes | str, *, what: str = "the body", tip: str = "") -> Any:
    """``raw`` parsed as JSON; ``what`` names it in errors (``"the body"``, ``"the message"``).

    Raises:
        ApiError: ``"invalid"``, with one line saying what is wrong.
    """
    try:
        return json.loads(raw)
    except RecursionError:
        raise ApiError("invalid", f"{what} is nested too deeply", tip=tip) from None
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise ApiError("invalid", f"{what} is not valid JSON: {exc}", tip=tip) from None
    except ValueError:  # int() of more digits than sys.get_int_max_str_digits()
        raise ApiError("invalid", f"{what} holds a number with too many digits", tip=tip) from None
