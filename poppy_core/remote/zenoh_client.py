"""``ZenohClient``: ``HttpClient``'s requests sent to a robot's ``poppy/NAME/api`` over Zenoh.

A ``RemoteRobot("zenoh:NAME")`` speaks through it: the robot's REST app answers in-process, so
its answers and refusals are the HTTP ones, turned into the same poppy errors.
"""

from __future__ import annotations

import json
import logging
import os
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

from poppy_core import zenoh_auth, zenoh_wire
from poppy_core.errors import BusTimeout, CommunicationError
from poppy_core.remote.client import DEFAULT_TIMEOUT_S, HttpClient

if TYPE_CHECKING:
    import zenoh

SCHEME = "zenoh:"
logger = logging.getLogger(__name__)

CONNECT_ENV = "POPPY_ZENOH_CONNECT"
"""Endpoints to connect to (comma-separated) when none are given."""
CONFIG_ENV = "POPPY_ZENOH_CONFIG"
"""A Zenoh configuration file to use when none is given."""
DEFAULT_CONNECT = ("tcp/127.0.0.1:7447",)
"""Zenoh's own default endpoint: a ``zenohd`` router (or a robot) on this computer."""


def client_settings(
    connect: tuple[str, ...] = (), config_file: Path | None = None, scout: bool = False
) -> zenoh_wire.ZenohSettings:
    """A client's Zenoh settings: those given, else ``POPPY_ZENOH_CONNECT`` /
    ``POPPY_ZENOH_CONFIG``, else a connection to ``tcp/127.0.0.1:7447`` (never listening)."""
    if not connect:
        connect = tuple(e.strip() for e in os.environ.get(CONNECT_ENV, "").split(",") if e.strip())
    if config_file is None and os.environ.get(CONFIG_ENV):
        config_file = Path(os.environ[CONFIG_ENV])
    if not connect and config_file is None and not scout:
        connect = DEFAULT_CONNECT
    return zenoh_wire.ZenohSettings(connect=connect, config_file=config_file, scout=scout)


def robot_name(url: str) -> str | None:
    """NAME of ``zenoh:NAME`` (None for another URL)."""
    if not url.startswith(SCHEME):
        return None
    return zenoh_wire.check_name(url[len(SCHEME) :])


class ZenohClient(HttpClient):
    """Requests to the robot ``name`` over Zenoh (``HttpClient``'s interface).

    Args:
        name: the robot's name (``poppy/NAME``).
        token: signs every request when set (``zenoh_auth``: the token itself is never sent).
        timeout_s: how long to wait for an answer.
        settings: how to join the Zenoh network (``client_settings()`` when None).
        session: an open session to use (kept open on ``close``) instead of opening one.

    Raises:
        ConfigError: a bad name, endpoint or configuration.
        MissingExtraError: eclipse-zenoh is not installed (the ``fleet`` extra).
    """

    def __init__(
        self,
        name: str,
        token: str | None = None,
        timeout_s: float = DEFAULT_TIMEOUT_S,
        *,
        settings: zenoh_wire.ZenohSettings | None = None,
        session: zenoh.Session | None = None,
    ) -> None:
        self.name = zenoh_wire.check_name(name)
        self.base_url = f"{SCHEME}{self.name}"
        self.token = token
        self.timeout_s = timeout_s
        self._owned = session is None
        settings = settings or client_settings()
        self.session = session or zenoh_wire.open_session(settings)
        self._key = zenoh_wire.robot_key(name, "api")
        self.sender = zenoh_wire.sender_of(self.session)
        """Who signs this client's requests (for the robot's log)."""
        if self._owned:  # a new session: let its links come up and the robot be seen
            zenoh_wire.await_peers(self.session, settings, timeout_s)
            zenoh_wire.await_token(self.session, name, min(timeout_s, 3.0))

    def request(self, method: str, path: str, body: Any = None) -> Any:
        """Send a request; the decoded answer (as ``HttpClient.request``).

        Raises:
            CommunicationError: no robot of that name on the network.
            BusTimeout: it did not answer within ``timeout_s``.
            UnknownNameError, ConfigError, RegisterError: refused, as over HTTP.
        """
        status, answer = self.call(method, path, body)
        return self._decode(
            method, path, status, b"" if answer is None else json.dumps(answer).encode()
        )

    def image(self, path: str) -> bytes:
        """The bytes of an image the robot answers (its ``{"media_type", "base64"}`` body).

        Raises:
            CommunicationError, BusTimeout, ConfigError: as ``request``.
        """
        import base64
        import binascii

        status, answer = self.call("GET", path)
        if status >= 400:
            self._decode("GET", path, status, json.dumps(answer).encode())  # raises its error
        if not isinstance(answer, dict) or "base64" not in answer:
            raise CommunicationError(f"{self.base_url}: GET {path} is not an image", port=path)
        try:
            return base64.b64decode(answer["base64"], validate=True)
        except (binascii.Error, TypeError) as exc:
            raise CommunicationError(f"{self.base_url}: a bad image ({exc})", port=path) from None

    def call(
        self, method: str, path: str, body: Any = None, start_at: float | None = None
    ) -> tuple[int, Any]:
        """The robot's status and answer (undecoded: refusals are returned, not raised)."""
        payload = zenoh_wire.api_request(
            method,
            path,
            body,
            token=self.token,
            start_at=start_at,
            robot=self.name,
            sender=self.sender,
        )
        timeout = self.timeout_s + (max(0.0, start_at - time.time()) if start_at else 0.0)
        began = time.monotonic()
        try:
            replies = zenoh_wire.ask(self.session, self._key, payload, timeout).wait()
        except Exception as exc:  # the session is closed
            raise CommunicationError(f"{self.base_url}: {exc}", port=self.base_url) from None
        nonce = zenoh_auth.nonce_of(payload)
        waited = time.monotonic() - began
        return answer_of(self.base_url, replies, timeout, waited, token=self.token, nonce=nonce)

    def close(self) -> None:
        """Close the session if this client opened it."""
        if self._owned:
            self.session.close()  # type: ignore[no-untyped-call]


def answer_of(
    where: str,
    replies: list[Any],
    timeout_s: float,
    waited_s: float,
    *,
    token: str | None = None,
    nonce: str | None = None,
) -> tuple[int, Any]:
    """The status and body of the one reply of a robot's ``api`` (errors as ``reply_of``)."""
    reply = reply_of(where, replies, timeout_s, waited_s, token=token, nonce=nonce)
    return reply["status"], reply.get("body")


def reply_of(
    where: str,
    replies: list[Any],
    timeout_s: float,
    waited_s: float,
    *,
    token: str | None = None,
    nonce: str | None = None,
) -> dict[str, Any]:
    """The one reply of a robot's ``api``: ``{"status": int, "body", ...}`` (``start_at``,
    ``late_s`` of a timed request). Errors for none or a bad one: no reply before the timeout
    ran out is a robot that does not answer; none at once, a robot no one serves.

    A request signed with ``token`` (its ``nonce``) takes only an answer the robot signed
    for it (``zenoh_auth.reply_checks``); another session answering ``poppy/NAME/api`` (a
    stranger on the network) is ignored, with a WARNING, and when only such answers came the
    request fails saying so. Unsigned, two different answers (two sessions answer the name)
    fail rather than one being taken at random.
    """
    answers = [_answer(where, reply) for reply in replies if reply.ok is not None]
    if answers and token and nonce:
        signed = [a for a in answers if zenoh_auth.reply_checks(token, nonce, a)]
        if signed and len(signed) < len(answers):
            logger.warning(
                "%s: %d answer(s) not signed by the robot were ignored: another session "
                "answers this robot's name on the network (a stranger?)",
                where,
                len(answers) - len(signed),
            )
        if not signed:
            raise CommunicationError(
                f"{where}: no answer signed with the token came (answered: "
                f"{_detail(answers[0])}): the robot has no token, another one or an older "
                "poppy, or another session answers its name on this network",
                port=where,
            )
        return _plain(signed[0])
    if answers:
        if any(_plain(a) != _plain(answers[0]) for a in answers[1:]):
            raise CommunicationError(
                f"{where}: {len(answers)} different answers to one request: more than one "
                "session answers this robot's name on the network (two robots of one name, or "
                "a stranger); serve the robots with a token so their answers are signed",
                port=where,
            )
        return _plain(answers[0])
    if not replies and waited_s < timeout_s * 0.9:
        raise CommunicationError(
            f"{where}: no robot of that name on the Zenoh network (`poppy fleet list` shows "
            "the robots seen; check the endpoints: --zenoh-connect or POPPY_ZENOH_CONNECT)",
            port=where,
        )
    errors = list(dict.fromkeys(r.err.payload.to_bytes().decode(errors="replace") for r in replies))
    # Zenoh's own reply when the time ran out; a router or the robot's session, timing the
    # query out too, may send one of their own before the client's (a loaded machine)
    if not replies or errors == ["Timeout"]:
        raise BusTimeout(
            f"{where}: no answer within {timeout_s:g} s (is the robot served with "
            "`poppy serve --zenoh` and reachable? `poppy fleet list` shows the robots seen)",
            port=where,
        )
    raise CommunicationError(f"{where}: {'; '.join(errors)}", port=where)


def _answer(where: str, reply: Any) -> dict[str, Any]:
    """One answer's JSON object with an int ``status`` (CommunicationError: not a poppy one)."""
    try:
        answer = json.loads(reply.ok.payload.to_bytes())
        return {**answer, "status": int(answer["status"])}
    except (ValueError, KeyError, TypeError) as exc:
        raise CommunicationError(f"{where}: not a poppy answer ({exc})", port=where) from None


def _plain(answer: dict[str, Any]) -> dict[str, Any]:
    """An answer without its signature."""
    return {k: v for k, v in answer.items() if k != zenoh_auth.REPLY_MAC}


def _detail(answer: dict[str, Any]) -> str:
    body = answer.get("body")
    detail = body.get("detail") if isinstance(body, dict) else None
    return f"{answer['status']} {detail}" if detail else str(answer["status"])
