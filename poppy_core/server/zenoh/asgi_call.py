"""``AsgiCaller``: run one HTTP request through the REST app in-process, on a loop of its own.

The Zenoh queryable ``poppy/NAME/api`` answers v1 requests with the REST app itself, through
httpx's ``ASGITransport``, so a request over Zenoh meets the same routes, service operations,
token, checks and error mapping (``server/errors.py``) as one over HTTP. A route that
raises is answered 500 with its one line (never silence); closing cancels the requests still
under way and lets each of them answer before the loop ends.
"""

from __future__ import annotations

import asyncio
import base64
import json
import logging
import threading
from collections.abc import Awaitable
from typing import Any

logger = logging.getLogger(__name__)

HOST = "127.0.0.1"
"""The Host header of a request over Zenoh: a loopback name, which the Host check answers."""
BINARY_TYPES = frozenset({"image/jpeg", "image/png", "application/octet-stream"})
"""Answers sent over Zenoh in base64 (JSON carries no bytes): a camera's frame."""


class AsgiCaller:
    """Calls ``app`` from any thread; its coroutines run on one event loop in a daemon thread."""

    def __init__(self, app: Any) -> None:
        self.app = app
        self.loop = asyncio.new_event_loop()
        self._thread = threading.Thread(target=self._run, name="zenoh-api", daemon=True)
        self._thread.start()

    def _run(self) -> None:
        asyncio.set_event_loop(self.loop)
        self.loop.run_forever()

    def submit(self, coroutine: Awaitable[None]) -> None:
        """Run ``coroutine`` on the loop (a failure is logged)."""

        async def guarded() -> None:
            try:
                await coroutine
            except asyncio.CancelledError:
                pass  # closing: the coroutine answered as it was cancelled
            except Exception:
                logger.exception("a Zenoh request failed")

        asyncio.run_coroutine_threadsafe(guarded(), self.loop)

    async def call(
        self,
        method: str,
        path: str,
        body: Any = None,
        token: str | None = None,
        client: str = "zenoh",
    ) -> tuple[int, Any]:
        """The status and decoded JSON answer of ``method path`` (``body`` sent as JSON);
        ``client`` is who the app sees asking (its logs name it). A binary answer (a camera's
        frame) is ``{"media_type", "base64"}``. A route that raises gives 500 and the
        failure's line (the app's own 500 when it sent one first)."""
        import httpx

        headers = {"host": HOST, "accept": "application/json"}
        if token:
            headers["authorization"] = f"Bearer {token}"
        request = httpx.Request(
            method.upper(),
            f"http://{HOST}{path}",
            headers=headers,
            content=None if body is None else json.dumps(body).encode(),
        )
        if body is not None:
            request.headers["content-type"] = "application/json"
        failure: list[Exception] = []

        async def app(scope: Any, receive: Any, send: Any) -> None:
            try:
                await self.app(scope, receive, send)
            except Exception as exc:  # the app's error middleware answers first, then re-raises
                logger.warning("zenoh: %s %s failed: %s", method, path, exc, exc_info=exc)
                failure.append(exc)
                raise

        transport = httpx.ASGITransport(app, raise_app_exceptions=False, client=(client, 0))
        response = await transport.handle_async_request(request)
        data = await response.aread()
        if failure and not data:
            exc = failure[0]
            return 500, {"detail": f"the route failed: {type(exc).__name__}: {exc}"}
        media_type = response.headers.get("content-type", "").split(";")[0].strip()
        if data and media_type in BINARY_TYPES:
            encoded = base64.b64encode(data).decode("ascii")
            return response.status_code, {"media_type": media_type, "base64": encoded}
        try:
            return response.status_code, json.loads(data) if data else None
        except ValueError:
            return response.status_code, data[:200].decode("utf-8", errors="replace")

    def close(self, timeout_s: float = 2.0) -> None:
        """Cancel the requests under way (each answers as it is cancelled: a request held for
        its start time says the robot stops), let them end, then stop the loop: no task is
        left pending when it closes."""
        if self.loop.is_running():
            try:
                asyncio.run_coroutine_threadsafe(_cancel_all(), self.loop).result(timeout_s)
            except Exception as exc:  # a task that would not end: the loop stops anyway
                logger.debug("zenoh: cancelling the requests under way: %s", exc)
            self.loop.call_soon_threadsafe(self.loop.stop)
        self._thread.join(timeout_s)
        if not self.loop.is_running():
            self.loop.close()


async def _cancel_all() -> None:
    """Cancel every task of the running loop but this one, and wait for them to end."""
    tasks = [t for t in asyncio.all_tasks() if t is not asyncio.current_task()]
    for task in tasks:
        task.cancel()
    await asyncio.gather(*tasks, return_exceptions=True)
