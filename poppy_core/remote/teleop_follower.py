"""``RemoteFollower``: a robot served by ``poppy serve --http`` as a teleoperation follower.

It speaks the server's WebSocket (``/api/v1/ws``, see ``poppy_core.server.teleop_channel``): one
``teleop.start``, then a ``teleop.goals`` message per tick, never one HTTP request per frame. The
server ramps at the start, writes each goal at once and holds the motors where they are when
the goals stop coming (its watchdog). The state frames the server streams give the follower's
positions (for ``--record``). Messages leave from a sender thread holding only the newest goals,
so a stalled network never blocks the teleoperation's loop. When the connection closes or goes
silent (no frame for ``LINK_TIMEOUT_S``; WebSocket pings close it soon after), it is opened
again with a growing delay, and the server resumes with a ramp.
"""

from __future__ import annotations

import json
import logging
import math
import threading
import time
import uuid
from collections.abc import Callable, Mapping, Sequence
from typing import Any
from urllib.parse import urlencode, urlsplit

from poppy_core.errors import CommunicationError, ConfigError
from poppy_core.remote.client import HttpClient, path_of
from poppy_core.schedule import Backoff, Worker

logger = logging.getLogger(__name__)

STREAM_PATH = "/api/v1/ws"
DEFAULT_WATCHDOG_S = 0.25
LINK_TIMEOUT_S = 1.0
"""No frame from the server for this long: the link is reported lost."""
PING_INTERVAL_S = 1.0
PING_TIMEOUT_S = 2.0
START_TIMEOUT_S = 5.0
RECONNECT_FIRST_S = 0.2
RECONNECT_MAX_S = 2.0


class RemoteFollower:
    """A served robot driven as a follower (``teleoperate(leader, RemoteFollower(url))``).

    Args:
        url: ``http://host:port`` of ``poppy serve --http``.
        token: the server's token, if it has one.
        rate_hz: the rate of the state frames asked of the server (the follower's positions).
        ramp_s: duration of the server's start and resume ramps (None: from the distance).
        watchdog_s: the server holds the motors when no goal came for this long.
        on_change: called with ``(state, reason)`` when the state changes (any thread).
        timeout_s: how long connecting and starting may take.

    Raises:
        ConfigError: a URL that is not ``http://host[:port]``, or a refused token.
        CommunicationError: the server cannot be reached.
    """

    def __init__(
        self,
        url: str,
        *,
        token: str | None = None,
        rate_hz: float = 50.0,
        ramp_s: float | None = None,
        watchdog_s: float = DEFAULT_WATCHDOG_S,
        on_change: Callable[[str, str], None] | None = None,
        timeout_s: float = START_TIMEOUT_S,
    ) -> None:
        self.url = url.rstrip("/")
        self.token = token
        self.rate_hz = rate_hz
        self.ramp_s = ramp_s
        self.watchdog_s = watchdog_s
        self.on_change = on_change
        self.timeout_s = timeout_s
        parts = urlsplit(self.url)
        if parts.scheme != "http" or not parts.hostname:
            raise ConfigError(f"{url!r} is not an http://host:port URL", field="url", value=url)
        query = urlencode({"rate_hz": f"{rate_hz:g}"})
        self.ws_url = f"ws://{parts.netloc}{parts.path.rstrip('/')}{STREAM_PATH}?{query}"
        http = HttpClient(self.url, token=token, timeout_s=timeout_s)
        try:
            infos = http.get(path_of("motors"))
        finally:
            http.close()
        self._names = [str(info["name"]) for info in infos]
        self._client_id = uuid.uuid4().hex
        self._lock = threading.Lock()
        self._ws: Any = None
        self._motors: list[str] = []
        self._positions: dict[str, float] = {}
        self._last_frame = 0.0
        self._state = "idle"
        self._reason = ""
        self._started = threading.Event()
        self._start_answer: dict[str, Any] = {}
        self._stopping = threading.Event()
        self._reconnecting = False
        self._outbox = threading.Condition()
        self._goals: dict[str, float] = {}
        self._messages: list[dict[str, Any]] = []
        self._sender: Worker | None = None
        self._receiver: Worker | None = None
        self._reconnector: Worker | None = None
        self.reconnects = 0
        self.errors: list[str] = []
        """Error messages the server sent (each once)."""

    # -- the Follower interface ------------------------------------------------------------------

    @property
    def motor_names(self) -> list[str]:
        """Every motor of the served robot."""
        return list(self._names)

    @property
    def state(self) -> str:
        """The server's session state, or ``link lost``."""
        with self._lock:
            if self._ws is None and self._state != "stopped" and self._motors:
                return "link lost"
            if self._ws is not None and time.monotonic() - self._last_frame > LINK_TIMEOUT_S:
                return "link lost"
            return self._state

    def start(self, motors: Sequence[str]) -> None:
        """Open the WebSocket and start a session on ``motors`` (stiff where they are).

        Raises:
            CommunicationError: the server cannot be reached or does not answer.
            ConfigError: the server refused (token, unknown motor, motors in use).
        """
        self._motors = list(motors)
        self._stopping.clear()
        self._connect()
        if self._sender is None:
            self._sender = Worker("teleop send", self._send_loop)
            self._sender.start()

    def send(self, targets: Mapping[str, float]) -> None:
        """Queue targets (newer ones replace those not sent yet); dropped while the link is
        down (the server holds). Never blocks."""
        with self._outbox:
            self._goals.update({k: float(v) for k, v in targets.items()})
            self._outbox.notify()

    def hold(self, reason: str) -> None:
        """Ask the server to hold where the motors are (never blocks)."""
        with self._outbox:
            self._goals.clear()
            self._messages.append({"type": "teleop.hold", "reason": reason})
            self._outbox.notify()

    def positions(self) -> dict[str, float]:
        """The last positions the server streamed (empty while the link is lost)."""
        if self.state == "link lost":
            return {}
        with self._lock:
            return {m: self._positions[m] for m in self._motors if m in self._positions}

    def stop(self) -> None:
        """End the session (the server holds the motors where they are) and close."""
        self._stopping.set()
        with self._outbox:
            self._goals.clear()
            self._messages.append({"type": "teleop.stop"})
            self._outbox.notify()
        deadline = time.monotonic() + 1.0
        while self._state != "stopped" and self._ws is not None and time.monotonic() < deadline:
            time.sleep(0.01)  # if the link is gone, the server's watchdog holds
        self.close()

    def close(self) -> None:
        """Close the WebSocket (the served robot keeps running)."""
        self._stopping.set()
        with self._outbox:
            self._outbox.notify()
        if self._reconnector is not None:  # first: a link it opens meanwhile is closed below
            self._reconnector.close(2.0)
        with self._lock:
            ws, self._ws = self._ws, None
        if ws is not None:
            ws.close()
        for worker in (self._sender, self._receiver):
            if worker is not None:
                worker.close(2.0)  # joins (but from its own thread)
        self._sender = None

    # -- connection ------------------------------------------------------------------------------

    def _connect(self) -> None:
        from websockets.exceptions import InvalidStatus, WebSocketException
        from websockets.sync.client import connect

        headers = {"Authorization": f"Bearer {self.token}"} if self.token else None
        try:
            ws = connect(
                self.ws_url,
                additional_headers=headers,
                open_timeout=self.timeout_s,
                ping_interval=PING_INTERVAL_S,
                ping_timeout=PING_TIMEOUT_S,
                close_timeout=1.0,
            )
            # Entered as its context manager would be (websockets 17 warns otherwise); the
            # threads below share it and close() ends it.
            ws.__enter__()
        except InvalidStatus as exc:
            status = exc.response.status_code
            if status == 401:
                raise ConfigError(f"{self.url} refused the token", field="token") from None
            raise CommunicationError(
                f"{self.ws_url}: refused (HTTP {status})", port=self.url
            ) from None
        except (OSError, TimeoutError, WebSocketException) as exc:
            raise CommunicationError(f"cannot reach {self.ws_url}: {exc}", port=self.url) from None
        self._started.clear()
        self._last_frame = time.monotonic()
        self._receiver = Worker("teleop ws", lambda stopping: self._receive(ws))
        self._receiver.start()
        start = {
            "type": "teleop.start",
            "motors": self._motors,
            "ramp_s": self.ramp_s,
            "watchdog_s": self.watchdog_s,
            "client": self._client_id,
        }
        try:
            ws.send(json.dumps(start))
        except (OSError, WebSocketException) as exc:
            ws.close()
            raise CommunicationError(f"{self.ws_url}: {exc}", port=self.url) from None
        if not self._started.wait(self.timeout_s):
            ws.close()
            error = self.errors[-1] if self.errors else "no answer to teleop.start"
            raise CommunicationError(f"{self.ws_url}: {error}", port=self.url)
        if self._start_answer.get("error"):
            ws.close()
            raise ConfigError(f"{self.url}: {self._start_answer['error']}", field="motors")
        with self._lock:
            self._ws = ws

    def _receive(self, ws: Any) -> None:
        try:
            for raw in ws:
                self._last_frame = time.monotonic()
                try:
                    data = json.loads(raw)
                except ValueError:
                    continue
                if isinstance(data, dict):
                    self._dispatch(data)
        except Exception as exc:  # closed, reset: reconnect below
            logger.debug("teleop stream ended: %s", exc)
        with self._lock:
            current = self._ws is ws
            if current:
                self._ws = None
        if current and not self._stopping.is_set():
            self._link_lost("the connection closed")

    def _dispatch(self, data: dict[str, Any]) -> None:
        kind = data.get("type")
        if kind == "teleop.started":
            self._start_answer = data
            self._started.set()
        elif kind == "teleop.state":
            self._changed(str(data.get("state")), str(data.get("reason", "")))
        elif kind == "teleop.stopped":
            self._changed("stopped", "the client stopped")
        elif "error" in data:
            message = str(data["error"])
            if message not in self.errors:
                self.errors.append(message)
                logger.warning("%s: %s", self.url, message)
            if not self._started.is_set():
                self._start_answer = {"error": message}
                self._started.set()
        else:
            positions = {}
            for name, state in data.items():
                value = state.get("present_position") if isinstance(state, dict) else None
                if isinstance(value, int | float) and math.isfinite(value):
                    positions[name] = float(value)
            with self._lock:
                self._positions.update(positions)

    def _send_loop(self, stopping: threading.Event) -> None:
        """Sends what ``send``/``hold``/``stop`` queued until closed (``_closed``: the outbox
        is the loop's wake-up, ``close`` notifies it)."""
        while True:
            with self._outbox:
                while not (self._goals or self._messages or self._closed()):
                    self._outbox.wait()
                messages, self._messages = self._messages, []
                goals, self._goals = self._goals, {}
            for message in messages:
                self._send(message)
            if goals:
                self._send({"type": "teleop.goals", "positions": goals})
            if self._closed():
                return

    def _closed(self) -> bool:
        return self._stopping.is_set() and not self._messages and self._ws is None

    def _send(self, message: dict[str, Any]) -> None:
        ws = self._ws
        if ws is None:
            return
        try:
            ws.send(json.dumps(message))
        except Exception as exc:
            logger.debug("teleop send failed: %s", exc)
            with self._lock:
                if self._ws is ws:
                    self._ws = None
            ws.close()
            self._link_lost(f"sending failed: {exc}")

    def _link_lost(self, reason: str) -> None:
        with self._lock:
            if self._reconnecting:
                return
            self._reconnecting = True
        logger.warning("link to %s lost (%s): reconnecting", self.url, reason)
        self._changed("link lost", reason)
        self._reconnector = Worker("teleop reconnect", self._reconnect)
        self._reconnector.start()

    def _reconnect(self, stopping: threading.Event) -> None:
        backoff = Backoff(RECONNECT_FIRST_S, RECONNECT_MAX_S)
        try:
            while not self._stopping.wait(backoff.delay_s):
                try:
                    self._connect()
                except (CommunicationError, ConfigError) as exc:
                    logger.debug("reconnecting to %s: %s", self.url, exc)
                    backoff.failed()
                    continue
                self.reconnects += 1
                logger.warning("link to %s back: the follower resumes with a ramp", self.url)
                return
        finally:
            with self._lock:
                self._reconnecting = False

    def _changed(self, state: str, reason: str) -> None:
        with self._lock:
            if state == self._state and reason == self._reason:
                return
            self._state, self._reason = state, reason
        if self.on_change is not None:
            try:
                self.on_change(state, reason)
            except Exception:
                logger.exception("follower state callback failed")
