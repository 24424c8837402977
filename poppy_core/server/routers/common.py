"""Helpers shared by the routers: raw JSON bodies (pypot's routes) and awaiting a goto."""

import asyncio
import time
from typing import Any

from starlette.requests import Request

from poppy_core.motion.straight_line import LinearMove
from poppy_core.robot import GotoHandle
from poppy_core.server.jsonio import parse_json

POLL_S = 0.01
WAIT_MARGIN_S = 2.0
"""A waiting request gives up this long after the motion should have ended."""

MISSING = object()

V1_WRITER = "v1"
"""The writer of the v1 API's goals (``RobotService.write``'s ``writer``): a strict surface,
whose goals a motor leased by another owner refuses (409). It never holds a lease itself."""

CHANGES_STATE: dict[str, Any] = {"x-changes-state": True}
"""``openapi_extra`` of a GET route that changes the robot (pypot's primitive controls): a page
of another site may not reach it through a link or an image, whatever spelling of the path it
uses (``poppy_core.server.state_routes``)."""


async def json_body(request: Request, *, default: Any = MISSING, tip: str = "") -> Any:
    """The request body parsed as JSON (``default`` for an empty body, if given).

    Raises:
        ApiError: not JSON (or empty without a default).
    """
    raw = await request.body()
    if not raw.strip() and default is not MISSING:
        return default
    return parse_json(raw, tip=tip)


async def wait_goto(handle: GotoHandle | LinearMove) -> bool:
    """Wait (without blocking the event loop) until ``handle`` is done; False on timeout."""
    deadline = time.monotonic() + handle.duration_s + WAIT_MARGIN_S
    while not handle.done:
        if time.monotonic() > deadline:
            return False
        await asyncio.sleep(POLL_S)
    return True


def truthy(value: Any) -> bool:
    """pypot's reading of ``wait``: true for ``true``, ``"true"``, ``"True"`` and ``1``."""
    return str(value) in {"true", "True", "1"}


def client_of(request: Request) -> str:
    """Where a request comes from, for a lease's label: its address (``zenoh:HOST (zenoh ZID)``
    through Zenoh's ``api``), "" when unknown."""
    client = request.client
    return client.host if client is not None else ""
