"""``Fleet``: the robots served on Zenoh (``poppy serve --zenoh``), seen and driven together.

Robots are found by their liveliness tokens ``poppy/NAME`` (a robot that goes leaves within its
lease), described by ``poppy/NAME/description``, watched through ``poppy/*/state`` and
``poppy/*/health``, and commanded through ``poppy/NAME/api`` with a shared wall-clock
``start_at`` so that they start together.
"""

from __future__ import annotations

import contextlib
import json
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, TypeVar

from poppy_core import checks, zenoh_auth, zenoh_wire
from poppy_core.errors import BusTimeout, CommunicationError, ConfigError
from poppy_core.remote.zenoh_client import client_settings, reply_of

if TYPE_CHECKING:
    import zenoh

T = TypeVar("T")

DEFAULT_TIMEOUT_S = 2.0
TIMEOUT_ENV = "POPPY_FLEET_TIMEOUT_S"
MAX_TIMEOUT_S = 60.0


def fleet_timeout_s() -> float:
    """How long a robot has to answer a fleet's command: ``$POPPY_FLEET_TIMEOUT_S`` when set (a
    slow network, busy robots), else ``DEFAULT_TIMEOUT_S`` (read at each call).

    Raises:
        ConfigError: the variable is not a number of seconds above 0, at most ``MAX_TIMEOUT_S``.
    """
    return checks.seconds_from_env(
        TIMEOUT_ENV,
        DEFAULT_TIMEOUT_S,
        high=MAX_TIMEOUT_S,
        zero=False,
        what="a time-out",
        example="5",
        unset=f"{DEFAULT_TIMEOUT_S:g} s",
    )


START_LEAD_S = 0.3
"""The least lead of a shared start (how far ahead of now it is set) when it is measured."""
LEAD_MARGIN = 3.0
"""A measured lead is the slowest robot's round trip times this: the command is one round trip,
and arming a start (a move loaded, a thread made) costs about another on a busy robot."""
MAX_LEAD_S = 30.0
"""The most lead a shared start gets (half what a robot accepts: ``MAX_START_DELAY_S``)."""


@dataclass(frozen=True)
class Outcome:
    """What one robot answered to a fleet command: ``ok``, and its answer or refusal."""

    name: str
    ok: bool
    status: int
    answer: Any
    late_s: float = 0.0
    """How late the command came for its shared start (0: in time); a late start runs at
    once, and the outcome is still ok."""

    @property
    def message(self) -> str:
        """The refusal's one line (REST's wording), or ``ok``."""
        if self.ok:
            return "ok"
        if isinstance(self.answer, dict):
            return str(self.answer.get("detail", self.answer.get("error", self.answer)))
        return str(self.answer)


class Fleet:
    """The robots of a Zenoh network.

    Args:
        settings: how to join it (``client_settings()`` when None).
        token: signs every command (``zenoh_auth``: the token itself is never sent).
        timeout_s: how long a robot has to answer (None: ``fleet_timeout_s()``).
        session: an open session to use (kept open on ``close``).
    """

    def __init__(
        self,
        settings: zenoh_wire.ZenohSettings | None = None,
        *,
        token: str | None = None,
        timeout_s: float | None = None,
        session: zenoh.Session | None = None,
    ) -> None:
        self.token = token
        self.timeout_s = fleet_timeout_s() if timeout_s is None else timeout_s
        self._owned = session is None
        settings = settings or client_settings()
        self.session = session or zenoh_wire.open_session(settings)
        self._declared: list[Any] = []
        self._sender = zenoh_wire.sender_of(self.session)
        self.last_start_at: float | None = None
        """The shared start time of the last command sent ``together``."""
        self.last_lead_s: float | None = None
        """How far ahead of the command that start was set (measured, or given)."""
        if self._owned:  # a new session: let its links come up before the first query
            zenoh_wire.await_peers(self.session, settings, self.timeout_s)

    def names(self) -> list[str]:
        """The robots alive now (by their liveliness tokens), sorted."""
        found = set()
        for reply in self.session.liveliness().get(
            f"{zenoh_wire.PREFIX}/*", timeout=self.timeout_s
        ):
            if reply.ok is not None:
                name = zenoh_wire.name_of(str(reply.ok.key_expr))
                if name:
                    found.add(name)
        return sorted(found)

    def wait_for(self, names: Sequence[str], timeout_s: float = 5.0) -> list[str]:
        """The robots of ``names`` seen within ``timeout_s`` (all of them, or fewer)."""
        end = time.monotonic() + timeout_s
        while True:
            seen = [n for n in names if n in set(self.names())]
            if len(seen) == len(names) or time.monotonic() >= end:
                return seen
            time.sleep(0.05)

    def describe(self, names: Sequence[str] | None = None) -> dict[str, dict[str, Any]]:
        """Name -> description of each robot alive (or of ``names``), in name order."""
        wanted = list(names) if names is not None else self.names()
        found = {
            name: described
            for name, described in zenoh_wire.descriptions(self.session, self.timeout_s).items()
            if name in wanted
        }
        return {n: found[n] for n in sorted(found)}

    def round_trip_s(self, names: Sequence[str], timeout_s: float | None = None) -> float | None:
        """The slowest round trip of a description query among the robots of ``names`` (asked
        all at once), None when none answered within ``timeout_s`` (else the fleet's)."""
        began = time.monotonic()
        wait = self.timeout_s if timeout_s is None else timeout_s
        pending = [
            self.session.get(zenoh_wire.robot_key(name, "description"), timeout=wait)
            for name in names
        ]
        slowest = None
        for handler in pending:  # each is read after the ones before: the last read is the max
            if any(reply.ok is not None for reply in handler):
                slowest = time.monotonic() - began
        return slowest

    def start_lead(self, names: Sequence[str]) -> float:
        """How far ahead a shared start of ``names`` is set: the slowest robot's round trip
        (``round_trip_s``) times ``LEAD_MARGIN``, at least ``START_LEAD_S``, at most
        ``MAX_LEAD_S``; a robot that does not answer counts for nothing (its command will say
        so)."""
        measured = self.round_trip_s(names)
        lead = START_LEAD_S if measured is None else measured * LEAD_MARGIN
        return min(MAX_LEAD_S, max(START_LEAD_S, lead))

    def answer_limit_s(self, names: Sequence[str]) -> float:
        """How long the answers of a command not started together are awaited: the fleet's
        timeout, or the slowest round trip of a description query (``round_trip_s``, given
        ``LEAD_MARGIN`` times the fleet's timeout) times ``LEAD_MARGIN`` when that is longer,
        at most ``MAX_LEAD_S``."""
        measured = self.round_trip_s(names, self.timeout_s * LEAD_MARGIN)
        longest = self.timeout_s if measured is None else measured * LEAD_MARGIN
        return min(MAX_LEAD_S, max(self.timeout_s, longest))

    def command(
        self,
        names: Sequence[str],
        method: str,
        path: str,
        body: Any = None,
        *,
        together: bool = True,
        lead_s: float | None = None,
        timeout_s: float | None = None,
    ) -> list[Outcome]:
        """Send one v1 request to every robot of ``names`` at once; with ``together`` each runs
        it at the same wall-clock time, ``lead_s`` from now (None: ``start_lead``, measured),
        and this returns once that time has come (a start is answered when armed, before it).
        A robot the command reaches after that time starts at once and its outcome says how
        late (``late_s``). A robot that does not answer within the timeout gets an outcome
        saying so (never a hang): ``timeout_s``, else for a command ``together`` the fleet's
        timeout, else (a stop) the answers are awaited as they arrive for the fleet's timeout or,
        when longer, the slowest round trip of a description query sent right after the command
        times ``LEAD_MARGIN`` (a loaded robot answers late, and is waited for: ``answer_limit_s``).
        """
        lead = 0.0
        if together:
            lead = self.start_lead(names) if lead_s is None else lead_s
        start_at = time.time() + lead if together else None
        self.last_start_at = start_at
        self.last_lead_s = lead if together else None
        timeout = (self.timeout_s if timeout_s is None else timeout_s) + lead
        measure = timeout_s is None and not together
        pending = []
        for name in names:
            payload = zenoh_wire.api_request(
                method,
                path,
                body,
                token=self.token,
                start_at=start_at,
                robot=name,
                sender=self._sender,
            )
            key = zenoh_wire.robot_key(name, "api")
            answers = zenoh_wire.ask(self.session, key, payload, MAX_LEAD_S if measure else timeout)
            pending.append((name, zenoh_auth.nonce_of(payload), answers))
        began = time.monotonic()
        if measure:
            timeout = self.answer_limit_s(names)
        outcomes = []
        for name, nonce, answers in pending:
            try:
                replies = answers.wait(max(0.0, began + timeout - time.monotonic()))
                waited = time.monotonic() - began
                reply = reply_of(
                    f"zenoh:{name}", replies, timeout, waited, token=self.token, nonce=nonce
                )
            except (BusTimeout, CommunicationError) as exc:
                outcomes.append(Outcome(name, False, 0, {"detail": str(exc)}))
                continue
            status = reply["status"]
            late = reply.get("late_s", 0.0)
            late_s = float(late) if isinstance(late, int | float) and late > 0 else 0.0
            outcomes.append(Outcome(name, status < 400, status, reply.get("body"), late_s))
        if start_at is not None:
            time.sleep(max(0.0, start_at - time.time()))
        return outcomes

    def on_state(
        self, callback: Callable[[str, zenoh_wire.RobotState], None], name: str = "*"
    ) -> None:
        """Call ``callback(name, state)`` for each state message (of every robot by default).

        It runs in Zenoh's thread: keep it short. A message that is not a state is skipped."""
        self._subscribe(f"{zenoh_wire.PREFIX}/{name}/state", zenoh_wire.unpack_state, callback)

    def on_health(self, callback: Callable[[str, dict[str, Any]], None]) -> None:
        """Call ``callback(name, health)`` for each health message (every second per robot)."""
        self._subscribe(f"{zenoh_wire.PREFIX}/*/health", _health_of, callback)

    def _subscribe(
        self, key: str, decode: Callable[[bytes], T], callback: Callable[[str, T], None]
    ) -> None:
        """Call ``callback(robot, decode(payload))`` for each sample on ``key``; a payload
        ``decode`` refuses (ConfigError) is skipped."""

        def received(sample: zenoh.Sample) -> None:
            robot = zenoh_wire.name_of(str(sample.key_expr))
            try:
                message = decode(sample.payload.to_bytes())
            except ConfigError:
                return
            if robot:
                callback(robot, message)

        self._declared.append(self.session.declare_subscriber(key, received))

    def on_presence(self, callback: Callable[[str, bool], None]) -> None:
        """Call ``callback(name, alive)`` as robots come (those already here too) and go."""
        import zenoh

        def changed(sample: zenoh.Sample) -> None:
            robot = zenoh_wire.name_of(str(sample.key_expr))
            if robot:
                callback(robot, sample.kind == zenoh.SampleKind.PUT)

        subscriber = self.session.liveliness().declare_subscriber(
            f"{zenoh_wire.PREFIX}/*", changed, history=True
        )
        self._declared.append(subscriber)

    def goals(self, name: str) -> Callable[[dict[str, float]], None]:
        """A function sending goal positions to the robot ``name`` (its ``goals`` stream)."""
        import zenoh

        publisher = self.session.declare_publisher(
            zenoh_wire.robot_key(name, "goals"),
            congestion_control=zenoh.CongestionControl.DROP,
            express=True,
        )
        self._declared.append(publisher)
        lock = threading.Lock()

        def send(goals: dict[str, float]) -> None:
            with lock:
                publisher.put(zenoh_wire.goals_message(goals, self.token, name, self._sender))

        return send

    def close(self) -> None:
        """Undeclare the subscribers; close the session if this fleet opened it."""
        for declared in reversed(self._declared):
            with contextlib.suppress(Exception):  # the session may be closed already
                declared.undeclare()
        self._declared = []
        if self._owned:
            self.session.close()  # type: ignore[no-untyped-call]

    def __enter__(self) -> Fleet:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def _health_of(payload: bytes) -> dict[str, Any]:
    """A health message's JSON object (ConfigError: not one)."""
    try:
        health = json.loads(payload)
    except ValueError as exc:
        raise ConfigError(f"not a health message: {exc}") from exc
    if not isinstance(health, dict):
        raise ConfigError("not a health message: not a JSON object")
    return health
