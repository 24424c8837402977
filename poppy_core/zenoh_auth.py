"""Signed messages on Zenoh: a fleet's commands prove the token without carrying it.

A client signs each ``api`` request and ``goals`` message: HMAC-SHA256, keyed by a key derived
from the token, over the exact bytes of the message, which name the robot it is for, the
wall-clock time it was signed and a random nonce. What travels is ``{"signed": TEXT, "mac":
HEX}``: whoever answers ``poppy/NAME/api`` or listens to every key sees the message and its
signature, never the token, and cannot make another one. The robot (``Verifier``) checks the
signature (constant time), then that the message is for this robot, signed within ``WINDOW_S``
of its clock, with a nonce it has not seen in that window: a stolen message replayed, sent to
another robot or kept for later is refused.

Signing the exact text (not a canonical rewrite of its fields) leaves nothing to disagree on
between the two sides: the robot parses the text it verified. A leaf: nothing of ours but errors.
"""

from __future__ import annotations

import hashlib
import heapq
import hmac
import json
import os
import threading
import time
from typing import Any

SCHEME = "poppy-zenoh-hmac-sha256-v1"
"""Mixed into the key: a signature of this scheme means nothing to another."""
WINDOW_S = 30.0
"""How far a message's signing time may be from the robot's clock (either way)."""
MAX_NONCES = 65536
"""Nonces remembered at most (a window of 100 Hz goal streams fits many times): a signer that
sends more within the window is refused until older nonces expire. Only messages whose signature
checked are remembered, so only a token holder can fill it."""
NONCE_BYTES = 16


class Refused(Exception):
    """A message the robot does not accept: ``status`` (401, 429) and a one-line ``detail``."""

    def __init__(self, status: int, detail: str) -> None:
        super().__init__(detail)
        self.status = status
        self.detail = detail


def key_of(token: str) -> bytes:
    """The signing key of ``token`` (never the token itself: what keys HMAC on Zenoh is not the
    bearer token HTTP takes)."""
    return hashlib.sha256(SCHEME.encode() + b"\0" + token.encode()).digest()


def sign(token: str, robot: str, message: dict[str, Any], sender: str = "") -> bytes:
    """``message`` for ``robot``, stamped (``t``, ``nonce``, ``from``) and signed with ``token``.

    Raises:
        TypeError: a message JSON cannot hold.
    """
    stamped = {
        **message,
        "robot": robot,
        "t": time.time(),
        "nonce": os.urandom(NONCE_BYTES).hex(),
    }
    if sender:
        stamped["from"] = sender
    text = json.dumps(stamped, separators=(",", ":"))
    mac = hmac.new(key_of(token), text.encode(), hashlib.sha256).hexdigest()
    return json.dumps({"signed": text, "mac": mac}).encode()


def is_signed(message: Any) -> bool:
    """True for a ``{"signed", "mac"}`` envelope."""
    return isinstance(message, dict) and "signed" in message


class Verifier:
    """The robot's side: opens the signed messages meant for it, refuses the others.

    Args:
        token: the robot's token (its key signs every message it accepts).
        robot: the robot's name (a message signed for another robot is refused).
        window_s: how far from the robot's clock a signing time may be.
        max_nonces: nonces remembered at most.
    """

    def __init__(
        self,
        token: str,
        robot: str,
        window_s: float = WINDOW_S,
        max_nonces: int = MAX_NONCES,
    ) -> None:
        self._key = key_of(token)
        self.robot = robot
        self.window_s = window_s
        self.max_nonces = max_nonces
        self._seen: set[str] = set()
        self._expiry: list[tuple[float, str]] = []  # a heap: (wall time it may go, nonce)
        self._lock = threading.Lock()

    def seal(self, nonce: str, answer: dict[str, Any]) -> dict[str, Any]:
        """``answer`` to the request of ``nonce``, signed with the robot's token
        (``seal_reply``): the client knows it came from the robot."""
        return seal_reply(self._key, nonce, answer)

    @property
    def remembered(self) -> int:
        """Nonces held now (at most ``max_nonces``)."""
        return len(self._seen)

    def open(self, envelope: Any) -> dict[str, Any]:
        """The message inside ``envelope`` (a parsed ``{"signed", "mac"}``), once checked.

        Raises:
            Refused: 401 for a message not signed with the robot's token, for another robot,
                signed too long ago (or ahead), or seen before; 429 when more messages came in
                the window than the robot remembers.
        """
        if not is_signed(envelope):
            raise Refused(401, "this robot needs signed requests: give the robot's token")
        text, mac = envelope.get("signed"), envelope.get("mac")
        if not isinstance(text, str) or not isinstance(mac, str):
            raise Refused(401, 'a signed message is {"signed": TEXT, "mac": HEX}')
        expected = hmac.new(self._key, text.encode(), hashlib.sha256).hexdigest()
        if not hmac.compare_digest(expected.encode(), mac.encode("ascii", "replace")):
            raise Refused(401, "wrong signature: missing or wrong token")
        try:
            message = json.loads(text)
        except (ValueError, RecursionError):
            message = None
        if not isinstance(message, dict):
            raise Refused(401, "the signed text is not a JSON object")
        if message.get("robot") != self.robot:
            raise Refused(401, f"signed for robot {message.get('robot')!r}: this is {self.robot!r}")
        stamp, nonce = message.get("t"), message.get("nonce")
        if isinstance(stamp, bool) or not isinstance(stamp, int | float):
            raise Refused(401, "a signed message needs its time 't'")
        if not isinstance(nonce, str) or not nonce:
            raise Refused(401, "a signed message needs its 'nonce'")
        now = time.time()
        if not abs(now - stamp) <= self.window_s:
            raise Refused(
                401,
                f"stale: signed {now - stamp:+.0f} s from this robot's clock (at most "
                f"{self.window_s:g} s either way: check both clocks, NTP)",
            )
        self._remember(nonce, stamp + self.window_s, now)
        return message

    def _remember(self, nonce: str, until: float, now: float) -> None:
        with self._lock:
            while self._expiry and self._expiry[0][0] < now:
                self._seen.discard(heapq.heappop(self._expiry)[1])
            if nonce in self._seen:
                raise Refused(401, "replayed: this message was received before")
            if len(self._seen) >= self.max_nonces:
                raise Refused(
                    429,
                    f"too many messages: over {self.max_nonces} in {self.window_s:g} s; "
                    "send fewer and try again",
                )
            self._seen.add(nonce)
            heapq.heappush(self._expiry, (until, nonce))


# -- signed answers ------------------------------------------------------------------------------

REPLY_MAC = "reply_mac"
"""The field of an answer that carries its signature (a client of an older poppy ignores it)."""


def _reply_text(nonce: str, answer: dict[str, Any]) -> bytes:
    """What an answer's signature covers: the request's nonce (an answer kept from another
    request does not fit this one) and the answer's fields, in one canonical JSON text."""
    fields = {k: v for k, v in answer.items() if k != REPLY_MAC}
    return b"poppy-reply\0" + nonce.encode() + b"\0" + json.dumps(fields, sort_keys=True).encode()


def seal_reply(key: bytes, nonce: str, answer: dict[str, Any]) -> dict[str, Any]:
    """``answer`` to the signed request ``nonce``, with its signature (``REPLY_MAC``) made with
    the signing key ``key`` (``key_of(token)``)."""
    mac = hmac.new(key, _reply_text(nonce, answer), hashlib.sha256).hexdigest()
    return {**answer, REPLY_MAC: mac}


def reply_checks(token: str, nonce: str, answer: dict[str, Any]) -> bool:
    """True when ``answer`` was signed with ``token`` for the request of ``nonce``: it came from
    a robot holding the token, for this request (not a stranger's answer, not a replayed one)."""
    mac = answer.get(REPLY_MAC)
    if not isinstance(mac, str):
        return False
    expected = hmac.new(key_of(token), _reply_text(nonce, answer), hashlib.sha256).hexdigest()
    return hmac.compare_digest(expected.encode(), mac.encode("ascii", "replace"))


def nonce_of(payload: bytes) -> str | None:
    """The nonce of a signed message (None for one that is not signed)."""
    try:
        envelope = json.loads(payload)
        nonce = json.loads(envelope["signed"])["nonce"] if is_signed(envelope) else None
    except (ValueError, KeyError, TypeError):
        return None
    return nonce if isinstance(nonce, str) else None
