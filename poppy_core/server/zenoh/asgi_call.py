"""``AsgiCaller``: run one HTTP request through the REST app in-process, on a loop of its own.

The Zenoh queryable ``poppy/NAME/api`` answers v1 requests with the REST app itself, so a
request over Zenoh meets the same token, checks and error wording as one over HTTP.
"""

from __future__ import annotations

import asyncio
import json
import logging
import threading
from collections.abc import Awaitable
from typing import Any
from urllib.parse import unquote

logger = logging.getLogger(__name__)

HOST = b"127.0.0.1"
"""The Host header of a request over Zenoh: a loopback name, which the Host check answers."""


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
            except Exception:
                logger.exception("a Zenoh request failed")

        asyncio.run_coroutine_threadsafe(guarded(), self.loop)

    async def call(
        self, method: str, path: str, body: Any = None, token: str | None = None
    ) -> tuple[int, Any]:
        """The status and decoded JSON answer of ``method path`` (``body`` sent as JSON)."""
        path, _, query = path.partition("?")
        payload = b"" if body is None else json.dumps(body).encode()
        headers = [(b"host", HOST), (b"accept", b"application/json")]
        if payload:
            headers.append((b"content-type", b"application/json"))
            headers.append((b"content-length", str(len(payload)).encode()))
        if token:
            headers.append((b"authorization", b"Bearer " + token.encode()))
        scope: dict[str, Any] = {
            "type": "http",
            "asgi": {"version": "3.0"},
            "http_version": "1.1",
            "method": method.upper(),
            "scheme": "http",
            "path": unquote(path),
            "raw_path": path.encode(),
            "query_string": query.encode(),
            "root_path": "",
            "headers": headers,
            "client": ("zenoh", 0),
            "server": ("127.0.0.1", 0),
        }
        sent = False
        status = 500
        chunks: list[bytes] = []

        async def receive() -> dict[str, Any]:
            nonlocal sent
            if not sent:
                sent = True
                return {"type": "http.request", "body": payload, "more_body": False}
            await asyncio.Event().wait()  # never: the app read the whole body
            return {"type": "http.disconnect"}

        async def send(message: dict[str, Any]) -> None:
            nonlocal status
            if message["type"] == "http.response.start":
                status = int(message["status"])
            elif message["type"] == "http.response.body":
                chunks.append(message.get("body", b""))

        await self.app(scope, receive, send)
        data = b"".join(chunks)
        try:
            return status, json.loads(data) if data else None
        except ValueError:
            return status, data[:200].decode("utf-8", errors="replace")

    def close(self) -> None:
        """Stop the loop (requests under way are dropped)."""
        if self.loop.is_running():
            self.loop.call_soon_threadsafe(self.loop.stop)
        self._thread.join(2.0)
        if not self.loop.is_running():
            self.loop.close()
