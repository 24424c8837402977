"""The Zenoh contract of a fleet: session settings, the robots' key expressions, the state message.

Shared by the robot's side (``poppy_core.server.zenoh``) and the clients' (``poppy_core.remote``,
``poppy fleet``), so both speak the same keys and bytes; a leaf: nothing of ours but the leaves.

Keys (``NAME`` a robot's name: ``checks.robot_name``, the rule of its mDNS name too): the
liveliness token ``poppy/NAME``; the state ``poppy/NAME/state`` (``pack_state``, every sync
cycle); ``poppy/NAME/health`` (JSON, every second); the queryables ``poppy/NAME/description``
and ``poppy/NAME/api`` (a v1 REST request in JSON, answered by the robot's REST app in-process:
the same checks, errors and token); the subscriber ``poppy/NAME/goals`` (goal positions as a
stream).
"""

from __future__ import annotations

import json
import logging
import math
import re
import socket
import struct
import threading
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from poppy_core import checks, zenoh_auth
from poppy_core.errors import ArgumentError, ConfigError
from poppy_core.extras import require

if TYPE_CHECKING:
    import zenoh

PREFIX = "poppy"
STATE_VERSION = 1
DEFAULT_LEASE_MS = 3000
"""The transport lease of our default configuration: a robot that vanishes without closing its
session (power cut, Wi-Fi gone) leaves ``poppy fleet list`` within it. A killed process closes
its TCP links, which its peers see at once."""
FLEET_PORT = 7447
"""Zenoh's own default port (what ``zenohd`` listens on)."""

_ENDPOINT = re.compile(r"[a-z0-9]+/\S+")
MODES = ("auto", "peer", "client")
_log = logging.getLogger(__name__)


def check_name(name: str) -> str:
    """``name`` as a robot's name (``checks.robot_name``: one DNS label, lower case, so that
    ``poppy/NAME`` and ``NAME.local`` name the same robot): ``Poppy`` -> ``poppy``.

    Raises:
        ConfigError: another name (with the rule).
    """
    try:
        return checks.robot_name(name)
    except ArgumentError as exc:
        raise ConfigError(str(exc), field="name", value=name) from None


def default_name() -> str:
    """The host's name as a robot name (its first label lower-cased, other characters as
    ``-``; ``poppy`` when nothing is left)."""
    return checks.robot_name_of_host(socket.gethostname())


def robot_key(name: str, *parts: str) -> str:
    """``poppy/NAME/part/...``."""
    return "/".join((PREFIX, check_name(name), *parts))


def name_of(key: str) -> str | None:
    """The robot name of ``poppy/NAME[/...]`` (None for another key)."""
    parts = str(key).split("/")
    return parts[1] if len(parts) >= 2 and parts[0] == PREFIX else None


@dataclass(frozen=True)
class ZenohSettings:
    """How a process joins the Zenoh network.

    Attributes:
        listen: endpoints to listen on (``tcp/127.0.0.1:7447``); none: listen nowhere.
        connect: endpoints of peers or routers to connect to.
        config_file: Zenoh's own JSON5 configuration (routers, TLS, access control); the
            endpoints above, when given, replace its own.
        scout: find peers by multicast scouting on the LAN (off unless asked).
        mode: Zenoh's session mode: ``peer``, ``client``, or ``auto`` (``mode_of``).
    """

    listen: tuple[str, ...] = ()
    connect: tuple[str, ...] = ()
    config_file: Path | None = None
    scout: bool = False
    mode: str = "auto"

    def __post_init__(self) -> None:
        if self.mode not in MODES:
            raise ConfigError(
                f"{self.mode!r} is not a Zenoh mode: write peer, client or auto", field="mode"
            )
        for endpoint in (*self.listen, *self.connect):
            if not _ENDPOINT.fullmatch(endpoint):
                raise ConfigError(
                    f"{endpoint!r} is not a Zenoh endpoint: write PROTOCOL/ADDRESS, e.g. "
                    "tcp/127.0.0.1:7447",
                    field="endpoint",
                )


def mode_of(settings: ZenohSettings) -> str | None:
    """The session mode ``settings`` ask for (None: the configuration file's own).

    ``auto`` is a client when the session listens nowhere, does not scout and connects to one
    endpoint (a router, or one robot): a Zenoh router relays between its clients and its peers
    but not between two peers that cannot reach each other (zenohd and rmw_zenoh's router,
    measured with eclipse-zenoh 1.10), and poppy's sessions that only connect out cannot be
    reached. Otherwise a peer: it listens, scouts, or links to several robots itself.
    """
    if settings.mode != "auto":
        return settings.mode
    if settings.config_file is not None:
        return None
    if not settings.listen and not settings.scout and len(settings.connect) == 1:
        return "client"
    return "peer"


def session_config(settings: ZenohSettings) -> zenoh.Config:
    """The Zenoh configuration of ``settings`` (``mode_of``, no scouting unless asked).

    Raises:
        ConfigError: the configuration file cannot be read or is not Zenoh's.
        MissingExtraError: eclipse-zenoh is not installed (the ``fleet`` extra).
    """
    require("zenoh", extra="fleet")
    import zenoh

    try:
        if settings.config_file is not None:
            config = zenoh.Config.from_file(str(settings.config_file))
        else:
            config = zenoh.Config()
            config.insert_json5("listen/endpoints", "[]")
            config.insert_json5("transport/link/tx/lease", str(DEFAULT_LEASE_MS))
        mode = mode_of(settings)
        if mode is not None:
            config.insert_json5("mode", json.dumps(mode))
        if settings.listen:
            config.insert_json5("listen/endpoints", json.dumps(list(settings.listen)))
        if settings.connect:
            config.insert_json5("connect/endpoints", json.dumps(list(settings.connect)))
        if settings.config_file is None or settings.scout:
            scout = json.dumps(settings.scout)
            config.insert_json5("scouting/multicast/enabled", scout)
            config.insert_json5("scouting/gossip/enabled", scout)
    except (zenoh.ZError, OSError, ValueError) as exc:
        where = settings.config_file or "the Zenoh settings"
        raise ConfigError(f"{where}: {exc}", field="zenoh") from None
    return config


def open_session(
    settings: ZenohSettings, wait_s: float | None = 3.0, config: zenoh.Config | None = None
) -> zenoh.Session:
    """A Zenoh session joined as ``settings`` say (``config``: their configuration, amended).

    A client's session opens only once its router (or robot) answers: it is tried again every
    quarter second for ``wait_s`` (None: until it answers, with one WARNING, as a served robot
    waits for the classroom's router; an interrupt stops the wait).

    Raises:
        ConfigError: a bad configuration, or an endpoint Zenoh cannot listen on or reach.
        MissingExtraError: eclipse-zenoh is not installed (the ``fleet`` extra).
    """
    if config is None:
        config = session_config(settings)
    import zenoh

    end = None if wait_s is None else time.monotonic() + wait_s
    warned = False
    while True:
        try:
            return zenoh.open(config)
        except zenoh.ZError as exc:
            message = zenoh_message(exc)
            waiting = mode_of(settings) == "client" and "Unable to connect" in message
            if waiting and end is not None and time.monotonic() >= end:
                raise ConfigError(
                    f"no Zenoh router or robot answers at {', '.join(settings.connect)}: start "
                    "the router (zenohd, or poppy fleet router) or the robot there, or check "
                    "the endpoint",
                    field="zenoh",
                ) from None
            if not waiting:
                raise ConfigError(
                    f"cannot open the Zenoh session ({message}): check --zenoh-listen / "
                    "--zenoh-connect",
                    field="zenoh",
                ) from None
            if not warned and end is None:
                _log.warning(
                    "no Zenoh router answers at %s yet: waiting for it",
                    ", ".join(settings.connect),
                )
                warned = True
            time.sleep(0.25)


class Answers:
    """The answers to one query as they arrive (``ask``): ``wait`` returns them once the query
    is over (every queryable answered, or Zenoh's timeout) or at a deadline of the caller's."""

    def __init__(self) -> None:
        self._replies: list[Any] = []
        self._lock = threading.Lock()
        self._over = threading.Event()

    def add(self, reply: Any) -> None:
        with self._lock:
            self._replies.append(reply)

    def over(self) -> None:
        self._over.set()

    def wait(self, timeout_s: float | None = None) -> list[Any]:
        """The answers come within ``timeout_s`` (None: until the query is over)."""
        self._over.wait(timeout_s)
        with self._lock:
            return list(self._replies)


def ask(session: zenoh.Session, key: str, payload: bytes, timeout_s: float) -> Answers:
    """A query of a robot's ``api`` whose every answer is kept (no consolidation: a second
    session answering the same name is seen, never silently merged with the robot's)."""
    import zenoh

    answers = Answers()
    session.get(
        key,
        zenoh.handlers.Callback(answers.add, answers.over),
        payload=payload,
        timeout=timeout_s,
        consolidation=zenoh.ConsolidationMode.NONE,
    )
    return answers


def zenoh_message(exc: BaseException) -> str:
    """Zenoh's error text without the places in its Rust sources it names."""
    text = re.sub(r"\s+at /\S+", "", str(exc)).replace("[", "").replace("]", "")
    return " ".join(text.split()).rstrip(".")


def await_peers(session: zenoh.Session, settings: ZenohSettings, wait_s: float = 3.0) -> bool:
    """Wait until ``session`` is linked to a peer or router (when ``settings`` connect to one);
    False when none came within ``wait_s``. A session opens before its links are up: a query
    sent at once would find no one."""
    if not settings.connect and settings.config_file is None and not settings.scout:
        return True
    end = time.monotonic() + wait_s
    while time.monotonic() < end:
        if list(session.info.peers_zid()) or list(session.info.routers_zid()):
            return True
        time.sleep(0.01)
    return False


def await_token(session: zenoh.Session, name: str, wait_s: float = 3.0) -> bool:
    """Wait until the liveliness token of robot ``name`` is seen; False after ``wait_s``."""
    seen = threading.Event()
    subscriber = session.liveliness().declare_subscriber(
        robot_key(name), lambda sample: seen.set(), history=True
    )
    try:
        return seen.wait(wait_s)
    finally:
        subscriber.undeclare()  # type: ignore[no-untyped-call]


# -- the state message -------------------------------------------------------------------------

STATE_FIELDS = ("present_position", "present_speed", "present_load", "present_temperature")
"""Per motor, in this order, as float32 (NaN: not read)."""
_HEAD = struct.Struct("<BBId")  # version, motors, sequence, wall-clock time of the read
_MOTOR = struct.Struct("<ffffB")  # the four fields, then flags
COMPLIANT = 1
ONLINE = 2


@dataclass(frozen=True)
class RobotState:
    """One state message: the sequence number, when it was read (``time.time()``) and per
    motor its fields (``STATE_FIELDS`` and ``compliant``, ``online``)."""

    seq: int
    stamp: float
    motors: dict[str, dict[str, Any]]


def descriptions(session: zenoh.Session, timeout_s: float) -> dict[str, dict[str, Any]]:
    """Name -> description of every robot that answers ``poppy/*/description`` within
    ``timeout_s``; a reply that is not a JSON object is skipped."""
    found: dict[str, dict[str, Any]] = {}
    for reply in session.get(f"{PREFIX}/*/description", timeout=timeout_s):
        if reply.ok is None:
            continue
        name = name_of(str(reply.ok.key_expr))
        try:
            described = json.loads(reply.ok.payload.to_bytes())
        except ValueError:
            continue
        if name and isinstance(described, dict):
            found[name] = described
    return found


def finite_or_nan(value: Any) -> float:
    """``value`` as a float; NaN for anything not a finite number (a value not read yet)."""
    try:
        number = float(value)
    except (TypeError, ValueError):
        return math.nan
    return number if math.isfinite(number) else math.nan


def _value(number: float) -> float | None:
    return None if number != number else round(number, 3)  # NaN: not read


def pack_state(seq: int, stamp: float, motors: Mapping[str, Mapping[str, Any]]) -> bytes:
    """Version 1: a 14-byte head, the motor names (UTF-8, ``\\n``-separated, length-prefixed),
    then 17 bytes per motor (four little-endian float32 and a flags byte)."""
    names = "\n".join(motors).encode()
    out = [_HEAD.pack(STATE_VERSION, len(motors), seq & 0xFFFFFFFF, stamp)]
    out.append(struct.pack("<H", len(names)) + names)
    for values in motors.values():
        flags = (COMPLIANT if values.get("compliant") else 0) | (
            ONLINE if values.get("online", True) else 0
        )
        out.append(_MOTOR.pack(*(finite_or_nan(values.get(f)) for f in STATE_FIELDS), flags))
    return b"".join(out)


def unpack_state(data: bytes) -> RobotState:
    """The message ``pack_state`` made.

    Raises:
        ConfigError: not a state message of a version this code reads.
    """
    try:
        version, count, seq, stamp = _HEAD.unpack_from(data, 0)
        if version != STATE_VERSION:
            raise ConfigError(
                f"state message version {version}: this poppy reads version {STATE_VERSION} "
                "(update poppy on one side)",
                field="state",
            )
        offset = _HEAD.size
        (size,) = struct.unpack_from("<H", data, offset)
        offset += 2
        names = data[offset : offset + size].decode().split("\n") if count else []
        offset += size
        block = data[offset : offset + count * _MOTOR.size]
        motors: dict[str, dict[str, Any]] = {}
        for name, (position, speed, load, temperature, flags) in zip(
            names, _MOTOR.iter_unpack(block), strict=True
        ):
            motors[name] = {
                "present_position": _value(position),
                "present_speed": _value(speed),
                "present_load": _value(load),
                "present_temperature": _value(temperature),
                "compliant": bool(flags & COMPLIANT),
                "online": bool(flags & ONLINE),
            }
    except (struct.error, UnicodeDecodeError, ValueError) as exc:
        raise ConfigError(f"not a poppy state message ({exc})", field="state") from None
    if len(motors) != count:
        raise ConfigError("not a poppy state message (motor count)", field="state")
    return RobotState(seq, stamp, motors)


def state_json(seq: int, stamp: float, motors: Mapping[str, Mapping[str, Any]]) -> bytes:
    """The same message as JSON (what ``bench fleet`` compares ``pack_state`` with)."""
    return json.dumps({"v": STATE_VERSION, "seq": seq, "t": stamp, "motors": motors}).encode()


def api_request(
    method: str,
    path: str,
    body: Any = None,
    *,
    token: str | None = None,
    start_at: float | None = None,
    robot: str | None = None,
    sender: str = "",
) -> bytes:
    """The payload of a query to ``poppy/NAME/api``: a v1 REST request (``start_at``: the
    wall-clock time the robot runs it at, for commands started together). With ``token`` it is
    signed for ``robot`` (``zenoh_auth.sign``): the token itself never travels."""
    request: dict[str, Any] = {"method": method, "path": path}
    if body is not None:
        request["body"] = body
    if start_at is not None:
        request["start_at"] = start_at
    if token:
        return zenoh_auth.sign(token, check_name(robot or ""), request, sender)
    return json.dumps(request).encode()


def goals_message(
    goals: Mapping[str, float],
    token: str | None = None,
    robot: str | None = None,
    sender: str = "",
) -> bytes:
    """The payload of ``poppy/NAME/goals``: motor -> goal position (degrees); signed for
    ``robot`` with ``token`` when one is given."""
    message: dict[str, Any] = {"goals": dict(goals)}
    if token:
        return zenoh_auth.sign(token, check_name(robot or ""), message, sender)
    if sender:  # unsigned: the robot still names the goal stream's owner after it
        message["from"] = sender
    return json.dumps(message).encode()


def sender_of(session: zenoh.Session) -> str:
    """Who signs from ``session``, for the robot's log: ``HOST (zenoh ZID)``."""
    return f"{socket.gethostname()} (zenoh {session.info.zid()})"


def names_list(names: Sequence[str]) -> str:
    """``a, b`` (or ``none``) for messages."""
    return ", ".join(names) or "none"
