"""``ZenohRobotServer``: a robot on Zenoh under ``poppy/NAME`` (``poppy serve --zenoh``).

It declares the liveliness token ``poppy/NAME`` (seen leaving when the robot goes), publishes
the state every sync cycle (``zenoh_wire.pack_state``) and the health every second, answers
``poppy/NAME/description`` and ``poppy/NAME/api`` (v1 REST requests run through the REST app
in-process by httpx's ASGITransport: the same service operations, token, checks and refusal
wording as HTTP, optionally at a shared wall-clock ``start_at``, which a start gets as its
route's explicit ``start_at``) and takes goal positions as a stream on ``poppy/NAME/goals`` (a
stream leases its motors, labelled with its sender, until it is silent for
``GOAL_STREAM_LAPSE_S``: goals for motors another owner drives are refused). Every
publication drops rather than waits (Zenoh's ``CongestionControl.DROP``): a subscriber that
cannot keep up never slows the robot.
"""

from __future__ import annotations

import asyncio
import json
import logging
import re
import socket
import threading
import time
from dataclasses import replace
from typing import TYPE_CHECKING, Any

from poppy_core import checks, zenoh_wire
from poppy_core.errors import PoppyError
from poppy_core.motion.chains import robot_chains
from poppy_core.motion.leases import Lease
from poppy_core.schedule import RateMeter, TickGuard, Worker
from poppy_core.server.errors import ApiError, refusal_kind
from poppy_core.server.reachable import reachable_endpoints, reachable_url
from poppy_core.server.start_time import late_by
from poppy_core.server.zenoh import described
from poppy_core.server.zenoh.asgi_call import AsgiCaller
from poppy_core.server.zenoh.intake import ApiRequest, Intake
from poppy_core.zenoh_auth import Refused

if TYPE_CHECKING:
    import zenoh

    from poppy_core.server.service import RobotService

logger = logging.getLogger(__name__)

DEFAULT_STATE_RATE_HZ = 50.0
"""The sync loop's default rate: one state message per cycle."""
HEALTH_PERIOD_S = 1.0
GOAL_STREAM_LAPSE_S = 1.0
"""A goal stream's lease ends this long after its last goals (the sender lost or done)."""
STARTS = re.compile(r"/api/v1/(primitives/[^/?]+/start|moves/[^/?]+/play)")
"""The requests whose action is armed for ``start_at`` (the route's own ``start_at`` argument,
put in the body: ``start_time``); any other request with a ``start_at`` is sent to the app at
that time."""


class ZenohRobotServer:
    """The robot of ``service`` on the Zenoh ``session`` as ``poppy/<name>``.

    Args:
        service: the robot service shared with the other servers.
        app: the REST app (built for this server when HTTP is not served) answering ``api``.
        session: an open Zenoh session (the server set's, shared with other Zenoh servers).
        name: the robot's name (one key chunk).
        token: signs every command (``api`` and ``goals``, ``zenoh_auth``): only messages
            signed with it, for this robot, recent and not seen before, are taken.
        state_rate_hz: state messages per second (the sync loop's rate).
        endpoints: where the session listens, for the description.
    """

    def __init__(
        self,
        service: RobotService,
        app: Any,
        session: zenoh.Session,
        name: str,
        *,
        token: str | None = None,
        state_rate_hz: float = DEFAULT_STATE_RATE_HZ,
        endpoints: tuple[str, ...] = (),
    ) -> None:
        self.service = service
        self.session = session
        self.name = zenoh_wire.check_name(name)
        self.token = token
        self.state_rate_hz = checks.rate(state_rate_hz, "state_rate_hz")
        self.endpoints = endpoints
        self.refused_goals = 0
        self.last_refusal: tuple[str, str] | None = None
        """The last goals refused: the refusal's kind (``errors.refusal_kind``; ``refused`` for
        one of the arrival checks) and its line."""
        self.published = 0
        self.rate = RateMeter()
        self._app = app
        self._caller: AsgiCaller | None = None
        self._declared: list[Any] = []
        self._publisher: Any = None
        self._health: Any = None
        self.page: str | None = None
        """The robot's web page (``http://...``), when it serves one, for the fleet's pages."""
        self._seen: set[str] = set()
        self._streams: dict[str, Lease] = {}
        """The goal streams' leases, by sender."""
        self.intake = Intake(self.name, token)
        """The arrival checks of ``api`` and ``goals`` (signature, shape, start time, places)."""
        self._worker = Worker.periodic(f"zenoh-state-{name}", self.state_rate_hz, self._tick)
        assert self._worker.ticker is not None
        self.state_loop = self._worker.ticker.guard
        """The state publication's failures (a raising tick is retried with backoff)."""
        self.health_loop = TickGuard(f"zenoh-health-{self.name}")
        self._next_health = 0.0
        self._lock = threading.Lock()
        self._declare_lock = threading.Lock()
        self._last_refusal = 0.0

    @property
    def url(self) -> str:
        """``zenoh:NAME``: what ``from_remote`` and ``--remote`` take."""
        return f"zenoh:{self.name}"

    @property
    def port(self) -> None:
        """No port of its own (the session's endpoints are in ``endpoints``)."""
        return None

    @property
    def running(self) -> bool:
        """True while the state is published."""
        return self._worker.running

    def key(self, *parts: str) -> str:
        """``poppy/NAME/...``."""
        return zenoh_wire.robot_key(self.name, *parts)

    def start(self) -> None:
        """Declare the queryables, the goal subscriber, then the liveliness token; publish."""
        if self.running:
            return
        self._caller = AsgiCaller(self._app)
        with self._declare_lock:
            self._declared = self._declare()
        self._next_health = 0.0
        self._worker.start()
        self._caller.submit(self._warm_up(self._caller))

    def _declare(self) -> list[Any]:
        """Everything under ``poppy/NAME`` for the current name (the token last)."""
        import zenoh

        session = self.session
        drop = zenoh.CongestionControl.DROP
        self._publisher = session.declare_publisher(
            self.key("state"), congestion_control=drop, express=True
        )
        self._health = session.declare_publisher(self.key("health"), congestion_control=drop)
        return [
            self._publisher,
            self._health,
            session.declare_queryable(self.key("api"), self._on_api),
            session.declare_queryable(self.key("description"), self._on_description),
            session.declare_subscriber(self.key("goals"), self._on_goals),
            session.liveliness().declare_subscriber(
                f"{zenoh_wire.PREFIX}/*", self._on_presence, history=True
            ),
            session.liveliness().declare_token(zenoh_wire.robot_key(self.name)),
        ]

    def rename(self, name: str) -> None:
        """Serve as ``poppy/<name>`` from now on (the page renamed the robot): everything is
        declared under the new name, then the old one is undeclared (the fleet sees the old
        name leave and the new one come); requests are signed for the new name."""
        name = zenoh_wire.check_name(name)
        with self._declare_lock:
            if name == self.name:
                return
            old, self.name = self._declared, name
            self.intake.rename(name)
            if self._declared:  # started: serve under the new name, then drop the old one
                self._declared = self._declare()
                _undeclare(old)
        logger.info("zenoh: the robot is now poppy/%s", name)

    async def _warm_up(self, caller: AsgiCaller) -> None:
        """One request through the app before any client's: its first one builds the routes'
        models and the worker threads (a first fleet command would start late by that)."""
        for name in list(self.service.primitives())[:1]:
            await caller.call("GET", f"/api/v1/primitives/{name}", token=self.token)
        await caller.call("GET", "/api/v1/moves/status", token=self.token)

    def stop(self) -> None:
        """Stop publishing, then undeclare everything (the token first: the fleet sees the
        robot leave), then the API's loop (requests still held are answered 503)."""
        self._worker.close()
        with self._declare_lock:
            declared, self._declared = self._declared, []
        if self._caller is not None:
            self._caller.close()
            self._caller = None
        _undeclare(declared)

    def seen(self) -> list[str]:
        """The robots alive on the network, by their liveliness tokens (this one too)."""
        with self._lock:
            return sorted(self._seen)

    def _on_presence(self, sample: zenoh.Sample) -> None:
        import zenoh

        name = zenoh_wire.name_of(str(sample.key_expr))
        if name:
            with self._lock:
                if sample.kind == zenoh.SampleKind.PUT:
                    self._seen.add(name)
                else:
                    self._seen.discard(name)

    # -- publications ------------------------------------------------------------------------

    def _tick(self, now: float) -> None:
        if now >= self._next_health:  # guarded apart: a failing state still has its health
            self._next_health = now + HEALTH_PERIOD_S
            self.health_loop.run(self._publish_health, self._worker.stopping)
        self._publish_state(now)

    def _publish_state(self, now: float) -> None:
        self._publisher.put(self.state_message())
        self.published += 1
        self.rate.tick(now)

    def _publish_health(self) -> None:
        self._health.put(json.dumps(self.health()).encode())

    def state_message(self) -> bytes:
        """The state of every motor now (``zenoh_wire.pack_state``)."""
        stamp = time.time()
        motors: dict[str, dict[str, Any]] = {}
        for motor in self.service.robot.motors:
            entry = {field: getattr(motor, field, None) for field in zenoh_wire.STATE_FIELDS}
            entry["compliant"] = motor.compliant
            entry["online"] = motor.online
            motors[motor.name] = entry
        return zenoh_wire.pack_state(self.published, stamp, motors)

    def health(self) -> dict[str, Any]:
        """The buses' health, the state rate and the goals refused."""
        buses = self.service.health()
        offline = sorted({m for bus in buses.values() for m in bus.get("offline", [])})
        ok = all(bus.get("connected", True) for bus in buses.values()) and not offline
        ok = ok and not self.state_loop.failing
        return {
            "name": self.name,
            "ok": ok,
            "offline": offline,
            "state_hz": round(self.rate.rate_hz, 1),
            "refused_goals": self.refused_goals,
            "publishing": self.state_loop.health(),
            "held": self.intake.held,
            "running": self.service.running_primitives(),
            "playing": self.service.moves.playing(),
            "buses": buses,
        }

    def description(self) -> dict[str, Any]:
        """Creature, motors (with limits), groups, primitives, moves, chains, cameras (those
        with a picture, else ``no_camera`` says why), host, endpoints."""
        robot = self.service.robot
        return {
            "version": zenoh_wire.STATE_VERSION,
            "name": self.name,
            "creature": described.creature(robot),
            "host": socket.gethostname(),
            # where a peer reaches it: a wildcard listener (0.0.0.0) is no address to dial
            "endpoints": reachable_endpoints(self.endpoints),
            "page": reachable_url(self.page),
            "token": self.token is not None,
            "state_rate_hz": self.state_rate_hz,
            "motors": described.motors(robot),
            "groups": self.service.groups(),
            "primitives": list(self.service.primitives()),
            "moves": self.service.moves.names(),
            "chains": list(robot_chains(robot)),
            **described.cameras(robot),
            "health": self.health(),
        }

    # -- queries -----------------------------------------------------------------------------

    def _on_description(self, query: zenoh.Query) -> None:
        try:
            query.reply(self.key("description"), json.dumps(self.description()).encode())
        except Exception:
            logger.exception("answering %s", query.key_expr)

    def _on_api(self, query: zenoh.Query) -> None:
        payload = query.payload.to_bytes() if query.payload is not None else b""
        key = self.key("api")  # the name the query reached (a rename may follow)
        caller = self._caller
        if caller is None:
            _reply(query, key, _refusal(503, "the robot is stopping"))
            return
        caller.submit(self._answer(caller, query, key, payload))

    async def _answer(
        self, caller: AsgiCaller, query: zenoh.Query, key: str, payload: bytes
    ) -> None:
        """Every request gets an answer: the route's, a refusal, 500 with the failure's line,
        or 503 when the robot stops while it is held."""
        try:
            answer = await self.api(caller, payload)
        except asyncio.CancelledError:
            _reply(query, key, _refusal(503, "the robot is stopping"))
            raise
        except Exception as exc:
            logger.warning("zenoh: %s: a request failed: %s", self.name, exc, exc_info=exc)
            answer = _refusal(500, f"the robot failed to answer: {type(exc).__name__}: {exc}")
        _reply(query, key, answer)

    async def api(self, caller: AsgiCaller, payload: bytes) -> dict[str, Any]:
        """The reply to one ``api`` request: ``{"status", "body"}`` (a refusal: REST's, or
        400/401/413/422/429 of its arrival), plus ``start_at`` when a start was armed for that
        time (answered on arrival: the start itself happens at ``start_at``), signed when the
        request was signed with the robot's token (``reply_mac``).

        Everything is checked on arrival (``Intake``: shape, signature, start time, a place
        among the requests held), before the robot holds anything for a start time."""
        try:
            request = self.intake.api(payload)
        except Refused as exc:
            return _refusal(exc.status, exc.detail)
        return self.intake.seal(request, await self._run(caller, request))

    async def _run(self, caller: AsgiCaller, request: ApiRequest) -> dict[str, Any]:
        """The answer to a request that passed its arrival checks: run now, armed for its
        start time, or run at that time."""
        if request.start_at is None:
            return await self._call(caller, request)
        try:
            place = self.intake.hold(request.start_at)
        except Refused as exc:
            return _refusal(exc.status, exc.detail)
        late = self._late_s(request)
        if STARTS.fullmatch(request.path):
            # armed now (checked, its thread made, held at a gate); the gate opens at start_at
            # (one already past: it starts at once, and the reply says how late)
            if request.body is not None and not isinstance(request.body, dict):
                self.intake.release(place)
                return _refusal(422, "the body of a start is an object (or nothing)")
            body = {**(request.body or {}), "start_at": request.start_at}
            reply = await self._call(caller, replace(request, body=body))
            if reply["status"] >= 400:
                self.intake.release(place)
                return reply
            return {**reply, "start_at": request.start_at, **late}
        try:
            await asyncio.sleep(max(0.0, request.start_at - time.time()))
            return {**await self._call(caller, request), **late}
        finally:
            self.intake.release(place)

    def _late_s(self, request: ApiRequest) -> dict[str, float]:
        """``{"late_s": S}`` for a request that came after its start time (``late_by``), else
        nothing."""
        late = late_by(request.start_at or 0.0)
        if late:
            logger.info(
                "zenoh: %s: %s came %.3f s late: run at once", self.name, request.path, late
            )
        return {"late_s": late} if late else {}

    async def _call(self, caller: AsgiCaller, request: ApiRequest) -> dict[str, Any]:
        """The app's answer: the request passed its arrival checks, so it carries the robot's
        own token (the sender proved it knows it)."""
        status, answer = await caller.call(
            request.method, request.path, request.body, self.token, client=request.sender
        )
        return {"status": status, "body": answer}

    # -- the goal stream ---------------------------------------------------------------------

    def _on_goals(self, sample: zenoh.Sample) -> None:
        try:
            self.apply_goals(sample.payload.to_bytes())
        except (Refused, ApiError, PoppyError, ValueError, TypeError, RecursionError) as exc:
            self.refused_goals += 1
            kind = "refused" if isinstance(exc, Refused) else refusal_kind(exc)
            now = time.monotonic()
            if now - self._last_refusal > 1.0:  # one line a second, whatever the rate
                self._last_refusal = now
                logger.warning("%s: goals refused (%s): %s", self.name, kind, exc)
            self.last_refusal = (kind, str(exc))

    def apply_goals(self, payload: bytes) -> dict[str, float]:
        """Check every goal of a ``goals`` message, then set them all (or none).

        Raises:
            Refused: not signed with the robot's token (or stale, replayed, for another
                robot), not a goals message (nothing moved).
            ApiError: a bad goal (nothing moved).
            UnknownMotorError: an unknown motor (nothing moved).
            CompliantMotorError: a goal to a compliant motor, which would not move it (the
                service's rule for poppy's own surfaces; nothing moved).
        """
        goals, sender = self.intake.goals(payload)
        with self._lock:
            lease = self._streams.get(sender)
            if lease is None or not lease.live():
                lease = Lease(
                    "goal stream",
                    client=sender,
                    holder=("zenoh", sender),
                    stop=f"stop sending: it ends {GOAL_STREAM_LAPSE_S:g} s after its last goals",
                    lapse_s=GOAL_STREAM_LAPSE_S,
                )
                self._streams = {k: v for k, v in self._streams.items() if v.live()}
                self._streams[sender] = lease
            return self.service.set_goals(
                goals, refuse_compliant=True, writer=lease.holder, lease=lease
            )


def _refusal(status: int, detail: str) -> dict[str, Any]:
    return {"status": status, "body": {"detail": detail}}


def _reply(query: zenoh.Query, key: str, answer: dict[str, Any]) -> None:
    try:
        query.reply(key, json.dumps(answer).encode())
    except Exception as exc:  # the session closed under it: the client's timeout says so
        logger.debug("zenoh: no reply sent: %s", exc)


def _undeclare(declared: list[Any]) -> None:
    """Undeclare in reverse order (the liveliness token first)."""
    for item in reversed(declared):
        try:
            item.undeclare()
        except Exception as exc:  # a session already closed
            logger.debug("undeclaring on Zenoh: %s", exc)
