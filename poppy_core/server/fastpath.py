"""A fast path for pypot's hottest routes: ``/robot.json``, ``/motors/list.json``, register
values (GET and POST) and ``/motors/goto.json`` (without ``wait``).

Web pages and Snap! poll and set register values many times a second; answering them here skips
FastAPI's routing and dependency solving (about twice the throughput). Anything unusual (an
unknown motor or register, a refused value, even a failure of this code) falls through to the
normal route, which formats the error. It sits inside the Host/Origin guard and the token check
(every request it answers passed them) and inside the body-size limit, which hands it the whole
body in one message.

The common cases cost the least: a body that is a plain JSON number for a number register is
read as ``json.loads`` reads it, without the general parser and pypot's spellings (a number is
its own spelling; the register's check still refuses what is not finite or too large), and an
answer holding one number is written as ``json`` writes it, without the encoder and the markup
escaping (a register name and a number hold no markup). docs/performance.md counts the calls.
"""

from __future__ import annotations

import re
from typing import Any

from starlette.types import ASGIApp, Message, Receive, Scope, Send

from poppy_core.server.jsonio import parse_json
from poppy_core.server.pypot_goto import goto_request
from poppy_core.server.pypot_json import pypot_bytes, pypot_raw_headers
from poppy_core.server.pypot_values import NUMBERS, pypot_value
from poppy_core.server.service import RobotService

REGISTER_VALUE = re.compile(r"^/motors/([A-Za-z0-9_]+)/registers/([A-Za-z0-9_]+)/value\.json$")
GOTO_PATH = "/motors/goto.json"
PLAIN_NUMBER = re.compile(rb"-?(?:0|[1-9][0-9]{0,15})(?:\.[0-9]{1,20})?(?:[eE][+-]?[0-9]{1,3})?")
"""A JSON number short enough to read directly (longer ones take the general parser)."""


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
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        path, method = scope["path"], scope["method"]
        if path == "/robot.json" and method == "GET":
            await _send(send, 200, self.service.description_json())
            return
        if path == "/motors/list.json" and method == "GET":
            await _send(send, 200, pypot_bytes({"motors": self.service.motor_names()}))
            return
        if path == GOTO_PATH and method == "POST":
            await self._goto(scope, receive, send)
            return
        match = REGISTER_VALUE.match(path)
        if match is None or method not in ("GET", "POST"):
            await self.app(scope, receive, send)
            return
        motor, register = match[1], match[2]
        if method == "GET":
            try:
                value = self.service.read(motor, register)
            except Exception:  # the route answers with the error (a 500 for a failure)
                await self.app(scope, receive, send)
                return
            await _answer(send, 200, register, value)
            return
        message, body = await _whole_body(receive)
        if body is None:
            await self.app(scope, _replay(message, receive), send)
            return
        try:
            value = plain_number(body) if register in NUMBERS else None
            if value is None:
                value = pypot_value(motor, register, parse_json(body))
            written = self.service.write(motor, register, value)
        except Exception:  # an unknown name, a refused value (or a failure): the route answers
            await self.app(scope, _replay(message, receive), send)
            return
        await _answer(send, 202, register, written)

    async def _goto(self, scope: Scope, receive: Receive, send: Send) -> None:
        """``/motors/goto.json`` without ``wait`` (a waiting one is the route's: it waits)."""
        message, body = await _whole_body(receive)
        try:
            if body is None:
                raise ValueError("not one whole body")
            targets, duration, wait = goto_request(parse_json(body))
            if wait:
                raise ValueError("a waiting goto")
            self.service.goto(targets, duration)  # checks everything before it starts
        except Exception:  # nothing started: the route answers (an error, or after the wait)
            await self.app(scope, _replay(message, receive), send)
            return
        answer = {"motors": targets, "duration": duration, "waiting": False}
        await _send(send, 202, pypot_bytes(answer))


async def _whole_body(receive: Receive) -> tuple[Message, bytes | None]:
    """The first message of a request and its body, None unless it holds the whole body (the
    body-size limit hands a body on in one message)."""
    message = await receive()
    if message["type"] != "http.request" or message.get("more_body", False):
        return message, None
    return message, message.get("body", b"")


async def _answer(send: Send, status: int, register: str, value: Any) -> None:
    await _send(send, status, register_body(register, value))


def plain_number(body: bytes) -> int | float | None:
    """``body`` read as ``json.loads`` reads it when it is a short plain JSON number, else None
    (the general parser's: other values, spaces, long numbers)."""
    if PLAIN_NUMBER.fullmatch(body) is None:
        return None
    return float(body) if b"." in body or b"e" in body or b"E" in body else int(body)


def register_body(register: str, value: Any) -> bytes:
    """``{register: value}`` as pypot's routes answer it (``pypot_json.pypot_bytes``).

    A finite float or an int (``%r`` is ``json``'s own spelling of both) is written directly:
    ``register`` matched ``REGISTER_VALUE``, so it needs no escaping.
    """
    kind = type(value)
    if (kind is float and value - value == 0.0) or kind is int:  # finite: inf - inf is nan
        return f'{{"{register}":{value!r}}}'.encode()
    return pypot_bytes({register: value})


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
