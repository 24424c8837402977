"""A Foxglove WebSocket client for the tests, written from the protocol's description
(foxglove.sdk.v1, the ws-protocol's successor): JSON control messages, binary data frames
(opcode 1: subscription id, log time, payload) and asset replies (opcode 4). Protobuf payloads
are decoded with the schema the server advertised (mcap-protobuf-support's decoder)."""

from __future__ import annotations

import asyncio
import base64
import json
import struct
import threading
from collections import defaultdict
from dataclasses import dataclass
from typing import Any

import websockets
from mcap.records import Schema
from mcap_protobuf.decoder import DecoderFactory

from tests.helpers.waiting import scaled

SUBPROTOCOL = "foxglove.sdk.v1"
MESSAGE_DATA = 1
FETCH_ASSET_RESPONSE = 4


@dataclass
class Message:
    topic: str
    log_time_ns: int
    payload: bytes
    decoded: Any


def decoder(channel: dict[str, Any]) -> Any:
    """A function decoding the channel's payloads (protobuf with its schema, or JSON)."""
    if channel["encoding"] == "json":
        return lambda data: json.loads(data)
    data = base64.b64decode(channel["schema"])
    schema = Schema(id=1, name=channel["schemaName"], encoding="protobuf", data=data)
    decode = DecoderFactory().decoder_for("protobuf", schema)
    assert decode is not None, channel
    return decode


class FoxgloveClient:
    """Connects to ``url`` in a thread of its own, subscribes to every channel advertised,
    keeps every message decoded (by topic) and answers asset requests."""

    def __init__(self, url: str) -> None:
        self.url = url
        self.server_info: dict[str, Any] = {}
        self.channels: dict[int, dict[str, Any]] = {}
        self.messages: dict[str, list[Message]] = defaultdict(list)
        self.assets: dict[int, tuple[int, str, bytes]] = {}
        self.errors: list[str] = []
        self._lock = threading.Lock()
        self._loop = asyncio.new_event_loop()
        self._ws: Any = None
        self._tasks: set[asyncio.Future[None]] = set()
        self._ready = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()
        # Ready once the server said who it is (its first message), not when the socket opened:
        # a loaded machine delivered serverInfo after a test had read an empty server_info.
        assert self._ready.wait(scaled(30)), "no serverInfo"
        assert self.server_info or not self.errors, self.errors

    def _run(self) -> None:
        self._loop.run_until_complete(self._main())

    async def _main(self) -> None:
        try:
            async with websockets.connect(
                self.url, subprotocols=[SUBPROTOCOL], close_timeout=2, max_size=None
            ) as ws:
                assert ws.subprotocol == SUBPROTOCOL
                self._ws = ws
                async for frame in ws:
                    self._on(frame)
        except websockets.ConnectionClosed:
            pass
        except Exception as exc:  # kept for the test to see
            self.errors.append(repr(exc))
        finally:
            self._ready.set()

    def _on(self, frame: str | bytes) -> None:
        if isinstance(frame, str):
            message = json.loads(frame)
            if message["op"] == "serverInfo":
                self.server_info = message
                self._ready.set()
            elif message["op"] == "advertise":
                fresh = []
                for channel in message["channels"]:
                    channel["decode"] = decoder(channel)
                    self.channels[channel["id"]] = channel
                    fresh.append({"id": channel["id"], "channelId": channel["id"]})
                self._send_now({"op": "subscribe", "subscriptions": fresh})
            return
        if frame[0] == MESSAGE_DATA:
            subscription, log_time = struct.unpack_from("<IQ", frame, 1)
            channel = self.channels[subscription]  # subscription ids are the channel ids
            payload = bytes(frame[13:])
            decoded = channel["decode"](payload)
            with self._lock:
                self.messages[channel["topic"]].append(
                    Message(channel["topic"], log_time, payload, decoded)
                )
        elif frame[0] == FETCH_ASSET_RESPONSE:
            request, status, length = struct.unpack_from("<IBI", frame, 1)
            error = frame[10 : 10 + length].decode()
            with self._lock:
                self.assets[request] = (status, error, bytes(frame[10 + length :]))

    def _send_now(self, message: dict[str, Any]) -> None:
        task = asyncio.ensure_future(self._ws.send(json.dumps(message)))
        self._tasks.add(task)
        task.add_done_callback(self._tasks.discard)

    def send(self, message: dict[str, Any]) -> None:
        asyncio.run_coroutine_threadsafe(self._ws.send(json.dumps(message)), self._loop).result(10)

    def fetch_asset(self, uri: str, request_id: int) -> None:
        self.send({"op": "fetchAsset", "uri": uri, "requestId": request_id})

    def topics(self) -> set[str]:
        return {c["topic"] for c in self.channels.values()}

    def of(self, topic: str) -> list[Message]:
        with self._lock:
            return list(self.messages.get(topic, []))

    def close(self) -> None:
        """Drop the connection (the server sees it go, as when Foxglove's tab closes)."""
        if self._ws is not None and self._thread.is_alive():
            self._loop.call_soon_threadsafe(self._ws.transport.abort)
        self._thread.join(30)
        assert not self._thread.is_alive()
        self._loop.close()
