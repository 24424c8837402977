"""The WebSocket stream: every motor's state pushed at a fixed rate, commands taken in.

Frames sent: ``{motor: {present_position, present_speed, present_load, present_temperature,
led}}`` (pypot's ws server). Frames received: ``{motor: {register: value}}``, checked in full
before anything is written; a refused command gets ``{"error": "..."}`` back. Messages with a
string ``type`` are teleoperation messages (``poppy_core.server.teleop_channel``: a client
streams goal positions, a watchdog holds the motors when they stop coming). The send loop runs in
its own task, so it keeps its rate whatever the client sends and whatever HTTP requests do.
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import logging
from typing import TYPE_CHECKING, Any

from starlette.applications import Starlette
from starlette.routing import WebSocketRoute
from starlette.websockets import WebSocket, WebSocketDisconnect, WebSocketDisconnected

from poppy_core import checks
from poppy_core.errors import ArgumentError, PoppyError
from poppy_core.schedule import Periodic
from poppy_core.server.errors import ApiError, refusal_kind
from poppy_core.server.jsonio import parse_json
from poppy_core.server.middleware import TokenMiddleware, token_protocol
from poppy_core.server.origin_guard import OriginGuard
from poppy_core.server.origins import OriginPolicy
from poppy_core.server.refusals import one_line
from poppy_core.server.service import RobotService
from poppy_core.server.teleop_channel import TeleopChannel

if TYPE_CHECKING:
    from fastapi import FastAPI

logger = logging.getLogger(__name__)

MIN_RATE_HZ = 0.1
MAX_RATE_HZ = 200.0
STREAM_PATH = "/api/v1/ws"


def clamp_rate(rate_hz: float) -> float:
    """A stream rate kept within [MIN_RATE_HZ, MAX_RATE_HZ] (NaN is refused, not clamped)."""
    return min(max(checks.number(rate_hz, "rate_hz"), MIN_RATE_HZ), MAX_RATE_HZ)


def check_rate(value: object) -> float:
    """A stream rate asked by a client: a number (or its text) within the stream's range."""
    return checks.in_range(
        checks.number_from(value, "rate_hz"), MIN_RATE_HZ, MAX_RATE_HZ, "rate_hz", "Hz"
    )


async def stream(websocket: WebSocket, service: RobotService, rate_hz: float | str) -> None:
    """Serve one WebSocket client until it leaves (``rate_hz`` as the client asked it)."""
    # a client that gave its token as a subprotocol must get it back (browsers require it)
    await websocket.accept(subprotocol=token_protocol(websocket.scope))
    try:
        rate_hz = check_rate(rate_hz)
    except ArgumentError as exc:  # an error frame, then a policy-violation close
        await websocket.send_text(json.dumps({"error": one_line(str(exc))}))
        await websocket.close(1008, "bad rate_hz")
        return
    send_lock = asyncio.Lock()

    async def send(data: Any) -> None:
        async with send_lock:
            await websocket.send_text(json.dumps(data))

    sender = asyncio.create_task(_send_states(send, service, rate_hz))
    loop = asyncio.get_running_loop()

    def notify(data: dict[str, Any]) -> None:  # from the teleop worker thread
        if not loop.is_closed():
            with contextlib.suppress(RuntimeError):
                asyncio.run_coroutine_threadsafe(_send_quietly(send, data), loop)

    peer = websocket.client
    channel = TeleopChannel(service.robot, service.teleop, notify, peer.host if peer else "")
    try:
        await _receive_commands(websocket, send, service, channel)
    except (WebSocketDisconnect, WebSocketDisconnected):
        pass  # the client left, maybe while an answer was on its way (after teleop.stop)
    except Exception:  # a bug: logged here, the client gets a close frame with a reason
        logger.exception("WebSocket stream failed")
        with contextlib.suppress(Exception):
            await websocket.close(1011, "internal error: the server's log has the details")
    finally:
        sender.cancel()
        with contextlib.suppress(asyncio.CancelledError, Exception):
            await sender
        await asyncio.to_thread(channel.close, "the connection closed")


async def _send_quietly(send: Any, data: Any) -> None:
    with contextlib.suppress(Exception):  # the connection may be gone
        await send(data)


async def _send_states(send: Any, service: RobotService, rate_hz: float) -> None:
    loop = asyncio.get_running_loop()
    # fell behind (slow client): one state at once, the periods missed before it skipped
    schedule = Periodic(1.0 / rate_hz, loop.time(), catch_up=1)
    while True:
        await send(service.state())
        schedule.advance(loop.time())
        await asyncio.sleep(max(0.0, schedule.next_deadline - loop.time()))


async def _receive_commands(
    websocket: WebSocket, send: Any, service: RobotService, channel: TeleopChannel
) -> None:
    while True:
        message = await websocket.receive()
        if message["type"] == "websocket.disconnect":
            return
        text = message.get("text")
        if text is None and message.get("bytes") is not None:
            text = message["bytes"].decode("utf-8", errors="replace")
        if text is None:
            continue
        try:
            data = parse_json(text, what="the message")
            if isinstance(data, dict) and isinstance(data.get("type"), str):
                reply = await _teleop(channel, data)
                if reply is not None:
                    await send(reply)
            else:
                service.write_many(data)
        except ApiError as exc:
            await send({"error": one_line(exc.message), "kind": exc.kind})
        except PoppyError as exc:
            await send({"error": one_line(str(exc)), "kind": refusal_kind(exc)})


async def _teleop(channel: TeleopChannel, data: dict[str, Any]) -> dict[str, Any] | None:
    """Goals are handled on the loop (cheap); start and stop touch the bus: in a thread."""
    if data["type"] == "teleop.goals":
        return channel.handle(data)
    return await asyncio.to_thread(channel.handle, data)


def _rate_from(websocket: WebSocket, default_hz: float) -> float | str:
    text = websocket.query_params.get("rate_hz")
    return text if text is not None else clamp_rate(default_hz)


def add_stream_routes(app: FastAPI) -> None:
    """Add ``/api/v1/ws`` (``?rate_hz=`` overrides the app's default rate)."""

    @app.websocket(STREAM_PATH)
    async def robot_stream(websocket: WebSocket) -> None:
        service = websocket.app.state.service
        await stream(websocket, service, _rate_from(websocket, websocket.app.state.stream_rate_hz))


def create_stream_app(
    service: RobotService,
    rate_hz: float = 30.0,
    token: str | None = None,
    policy: OriginPolicy | None = None,
) -> Any:
    """A small app serving the stream at ``/`` (pypot's ``--ws`` port).

    Args:
        service: the service of the HTTP app (``app.state.service``).
        rate_hz: the default rate.
        token: required from clients when set.
        policy: the Host and Origin rules (share the HTTP app's: ``app.state.policy``);
            loopback names and same-site pages only by default.
    """

    async def endpoint(websocket: WebSocket) -> None:
        await stream(websocket, service, _rate_from(websocket, rate_hz))

    app: Any = Starlette(routes=[WebSocketRoute("/", endpoint)])
    if token:
        app = TokenMiddleware(app, token)
    return OriginGuard(app, policy or OriginPolicy())
