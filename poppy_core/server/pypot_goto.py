"""pypot's ``/motors/goto.json`` body read into targets, a duration and ``wait``.

Shared by the route (``routers.pypot_motors``) and the fast path (``fastpath``), which answer the
same body the same way.
"""

from __future__ import annotations

from typing import Any

from poppy_core import checks
from poppy_core.errors import ArgumentError
from poppy_core.server.errors import ApiError
from poppy_core.server.routers.common import truthy

GOTOS_TIP = (
    '"motors" (names), "positions" (degrees, one per motor) and "duration" (seconds) are '
    'required, "wait" is optional. Example: {"motors": ["m1", "m2"], "positions": [90, 0], '
    '"duration": 2}'
)


def goto_number(value: Any, what: str, tip: str) -> float:
    """A number of a goto body (text read as a number too, as pypot's clients send it).

    Raises:
        ApiError: not a finite number.
    """
    try:
        return checks.number_from(value, what)
    except ArgumentError as exc:
        raise ApiError("invalid", str(exc), tip=tip) from None


def goto_request(data: Any) -> tuple[dict[str, float], float, bool]:
    """The targets (motor -> degrees), duration and ``wait`` of a ``/motors/goto.json`` body.

    Raises:
        ApiError: a missing key, lists of different lengths, a value that is not a number.
    """
    if not isinstance(data, dict) or not {"motors", "positions", "duration"} <= set(data):
        raise ApiError("invalid", "cannot read the data given", tip=GOTOS_TIP)
    motors, positions = data["motors"], data["positions"]
    if not isinstance(motors, list) or not isinstance(positions, list):
        raise ApiError("invalid", "motors and positions must be lists", tip=GOTOS_TIP)
    if len(motors) != len(positions):
        raise ApiError("invalid", "not as many positions as motors", tip=GOTOS_TIP)
    targets = {
        str(m): goto_number(p, f"position of {m}", GOTOS_TIP)
        for m, p in zip(motors, positions, strict=True)
    }
    duration = goto_number(data["duration"], "duration", GOTOS_TIP)
    return targets, duration, truthy(data.get("wait", False))
