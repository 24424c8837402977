"""A fast path for pypot's hottest routes: ``/robot.json`` and register values (GET and POST).

Web pages and Snap! poll and set register values many times a second; answering them here skips
FastAPI's routing and dependency solving (about twice the throughput). Anything unusual (an
unknown motor or register, a refused value) falls through to the normal route, which formats
the error. It sits inside the Host/Origin guard and the token check (every request it answers
passed them) and inside the body-size limit, which hands it the whole body in one message.
"""

from __future__ import annotations

import re
from typing import Any

from starlette.types import ASGIApp, Message, Receive, Scope, Send

from poppy_core.errors import PoppyError
from poppy_core.server.errors import ApiError
from poppy_core.server.jsonio import parse_json
from poppy_core.server.pypot_json import pypot_bytes, pypot_raw_headers
from poppy_core.server.pypot_values import pypot_value
from poppy_core.server.service import RobotService

REGISTER_VALUE = re.compile(r"^/motors/([A-Za-z0-9_]+)/registers/([A-Za-z0-9_]+)/value\.json$")


class RegisterFastPath:
    """Answer ``/robot.json`` and register reads and writes directly; pass the rest on.

    Args:
        app: the wrapped app.
        service: the robot service.
    """

    def __init__(self, app: ASGIApp, service: RobotService) -> None:
        self.app = app
        self.service = service

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] == "http" and scope["path"] == "/robot.json" and scope["method"] == "GET":
            await _send(send, 200, self.service.description_json())
            return
        match = REGISTER_VALUE.match(scope["path"]) if scope["type"] == "http" else None
        if match is None or scope["method"] not in ("GET", "POST"):
            await self.app(scope, receive, send)
            return
        motor, register = match[1], match[2]
        if scope["method"] == "GET":
            try:
                value = self.service.read(motor, register)
            except (ApiError, PoppyError):
                await self.app(scope, receive, send)  # the route answers with the error
                return
            await _answer(send, 200, {register: value})
            return
        message = await receive()
        body = message.get("body", b"") if message["type"] == "http.request" else b""
        if message["type"] != "http.request" or message.get("more_body", False):
            await self.app(scope, _replay(message, receive), send)
            return
        try:
            value = pypot_value(motor, register, parse_json(body))
            written = self.service.write(motor, register, value)
        except (ApiError, PoppyError):  # an unknown name, a refused value: the route answers
            await self.app(scope, _replay(message, receive), send)
            return
        await _answer(send, 202, {register: written})


async def _answer(send: Send, status: int, data: dict[str, Any]) -> None:
    await _send(send, status, pypot_bytes(data))


async def _send(send: Send, status: int, body: bytes) -> None:
    headers = pypot_raw_headers(len(body))  # pypot's type and headers, as the routes answer
    await send({"type": "http.response.start", "status": status, "headers": headers})
    await send({"type": "http.response.body", "body": body})


def _replay(first: Message, receive: Receive) -> Receive:
    sent = False

    async def replay() -> Message:
        nonlocal sent
        if not sent:
            sent = True
            return first
        return await receive()

    return replay
