"""``Intake``: what the robot checks in a Zenoh message on arrival, before any route runs or waits.

An ``api`` request or a ``goals`` message is checked the moment it arrives: its size and shape,
its signature (``zenoh_auth``: the token, the robot's name, the time window, the nonce) and its
``start_at``; a refusal is answered at once. A request held for its start time (an armed start,
or another request run at ``start_at``) takes one of ``MAX_ARMED`` places of the robot until that
time: the next one is refused (429) rather than kept, so a flood costs the robot nothing.
"""

from __future__ import annotations

import json
import threading
import time
from dataclasses import dataclass
from typing import Any

from poppy_core import zenoh_auth
from poppy_core.errors import ArgumentError
from poppy_core.server.middleware import MAX_BODY_BYTES
from poppy_core.server.start_time import check_start_at
from poppy_core.zenoh_auth import Refused

MAX_ARMED = 32
"""Requests a robot holds for their start time at once (armed starts and timed requests)."""
METHODS = ("GET", "PUT", "POST", "DELETE")
API_SHAPE = 'send {"method": "GET|PUT|POST|DELETE", "path": "/api/v1/...", "body": {...}}'


@dataclass(frozen=True)
class ApiRequest:
    """One ``api`` request that passed the checks of its arrival."""

    method: str
    path: str
    body: Any
    start_at: float | None
    sender: str
    """Who sent it, for the robot's log (``HOST (zenoh ZID)`` of a signed request)."""
    nonce: str = ""
    """The nonce of a request checked against the robot's token (its answer is signed)."""


class Intake:
    """The arrival checks of one robot's ``api`` and ``goals``.

    Args:
        name: the robot's name (signed messages must name it).
        token: the robot's token; with one, only messages signed with it are taken.
        max_armed: requests held for their start time at once.
    """

    def __init__(self, name: str, token: str | None, max_armed: int = MAX_ARMED) -> None:
        self.verifier = zenoh_auth.Verifier(token, name) if token is not None else None
        self.max_armed = max_armed
        self._held: list[float] = []
        self._lock = threading.Lock()

    def rename(self, name: str) -> None:
        """Messages are signed for ``name`` from now on."""
        if self.verifier is not None:
            self.verifier.robot = name

    def api(self, payload: bytes) -> ApiRequest:
        """The request in ``payload``, checked.

        Raises:
            Refused: 413 too big, 400 not a request, 401 not signed with the robot's token (or
                stale, replayed, for another robot), 422 a bad ``start_at``.
        """
        message = self._open(payload)
        method, path = message.get("method"), message.get("path")
        if method not in METHODS or not isinstance(path, str) or not path.startswith("/"):
            raise Refused(400, f"bad method or path: {API_SHAPE}")
        try:
            start_at = check_start_at(message.get("start_at"))
        except ArgumentError as exc:
            raise Refused(422, str(exc)) from None
        nonce = str(message["nonce"]) if self.verifier is not None else ""
        return ApiRequest(str(method), path, message.get("body"), start_at, _sender(message), nonce)

    def seal(self, request: ApiRequest, answer: dict[str, Any]) -> dict[str, Any]:
        """The answer to ``request``, signed with the robot's token when the request was
        checked against it (``zenoh_auth.seal_reply``): a client holding the token knows the
        robot answered, not a stranger answering ``poppy/NAME/api`` on the same network."""
        if self.verifier is None or not request.nonce:
            return answer
        return self.verifier.seal(request.nonce, answer)

    def goals(self, payload: bytes) -> tuple[dict[str, Any], str]:
        """The goals (motor -> degrees, unchecked values) of a ``goals`` message, and who sent
        them (``zenoh:HOST (zenoh ZID)``, ``zenoh`` when the message does not say).

        Raises:
            Refused: as ``api``, or 400 for a message without ``goals``.
        """
        message = self._open(payload)
        goals = message.get("goals")
        if not isinstance(goals, dict):
            raise Refused(400, 'expected {"goals": {motor: degrees}}')
        return goals, _sender(message)

    def _open(self, payload: bytes) -> dict[str, Any]:
        if len(payload) > MAX_BODY_BYTES:
            raise Refused(413, f"the message is over {MAX_BODY_BYTES} bytes")
        try:
            message = json.loads(payload)
        except (ValueError, RecursionError):
            raise Refused(400, f"the message is not JSON: {API_SHAPE}") from None
        if not isinstance(message, dict):
            raise Refused(400, f"the message is not an object: {API_SHAPE}")
        if self.verifier is not None:
            if "token" in message:
                raise Refused(
                    401,
                    "a token sent in clear is refused over Zenoh: update poppy where the "
                    "request comes from (it signs requests with the token instead)",
                )
            return self.verifier.open(message)
        if zenoh_auth.is_signed(message):  # a robot without a token takes signed requests too
            try:
                message = json.loads(message["signed"])
            except (TypeError, ValueError, RecursionError):
                raise Refused(400, "the signed text is not JSON") from None
            if not isinstance(message, dict):
                raise Refused(400, f"the message is not an object: {API_SHAPE}")
        return message

    def hold(self, start_at: float) -> float:
        """Take a place for a request held until ``start_at``; give it back with ``release``.

        Raises:
            Refused: 429 when ``max_armed`` requests are held already.
        """
        now = time.time()
        with self._lock:
            self._held = [t for t in self._held if t > now]
            if len(self._held) >= self.max_armed:
                raise Refused(
                    429,
                    f"{self.max_armed} requests are already waiting for their start time on "
                    "this robot: wait for them (or stop them) and send it again",
                )
            self._held.append(start_at)
        return start_at

    def release(self, start_at: float) -> None:
        """Give back a place ``hold`` took (a request refused or run)."""
        with self._lock:
            if start_at in self._held:
                self._held.remove(start_at)

    @property
    def held(self) -> int:
        """Requests held for a start time now."""
        now = time.time()
        with self._lock:
            return sum(1 for t in self._held if t > now)


def _sender(message: dict[str, Any]) -> str:
    sender = message.get("from")
    return f"zenoh:{sender}" if isinstance(sender, str) and sender else "zenoh"
