"""Teleoperation over the WebSocket: a client streams goal positions, a watchdog holds on silence.

Messages (JSON objects with a ``type``; the stream's ``{motor: {register: value}}`` commands
have no string ``type`` and are unchanged)::

    → {"type": "teleop.start", "motors": ["m1", ...] | null, "ramp_s": null, "watchdog_s": 0.25,
       "client": "an id of the client"}
    ← {"type": "teleop.started", "motors": [...], "positions": {...}, "watchdog_s": 0.25}
    → {"type": "teleop.goals", "positions": {"m1": 12.5, ...}}        (at the stream's rate)
    ← {"type": "teleop.state", "state": "ramping|following|held|stopped", "reason": "..."}
    → {"type": "teleop.hold", "reason": "..."}                        (the leader was lost)
    → {"type": "teleop.stop"}
    ← {"type": "teleop.stopped"}

Each connection has at most one session (a ``GoalStream``) and a worker thread that writes
the newest goals at once (a burst of late messages collapses into the newest) and holds the
motors where they are when no goals came for ``watchdog_s`` or the connection closes; the next
goals resume with a ramp. A motor is teleoperated by one connection at a time, except that a
client reconnecting with the same ``client`` id takes its motors over from its old connection
(which the server may not have seen close yet): a session leases its motors
(``motion/leases.py``), so a motor a move, a trajectory or a Zenoh goal stream drives refuses it,
and its motors refuse their goals while it lasts; the lease ends with the session (the client's
``teleop.stop``, the connection closed, the robot-wide stop).
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Mapping
from typing import Any

from poppy_core import checks
from poppy_core.motion.leases import STOP_ALL, Lease, MotorLeases
from poppy_core.motion.teleop.goal_stream import GoalStream, GoalStreamChange
from poppy_core.robot import Robot
from poppy_core.schedule import Worker
from poppy_core.server.errors import ApiError

DEFAULT_WATCHDOG_S = 0.25
WATCHDOG_RANGE_S = (0.05, 5.0)
MAX_RAMP_S = 30.0
TICK_S = 0.02
"""The worker wakes at least this often to check the watchdog."""
TIP = "see docs/teleop.md: teleop.start, then teleop.goals at your rate"

Notify = Callable[[dict[str, Any]], None]


class TeleopRegistry:
    """The WebSocket teleoperations of a robot: each session holds a lease on its motors
    (``motion/leases.py``: a motor has one owner at a time, whatever drives it)."""

    def __init__(self, leases: MotorLeases) -> None:
        self.leases = leases
        self._lock = threading.Lock()
        self._channels: dict[TeleopChannel, Lease] = {}

    def claim(self, channel: TeleopChannel, motors: list[str]) -> None:
        """Lease ``motors`` to ``channel`` (taking them from an older connection of its client).

        Raises:
            MotorLeasedError: another owner (another client's teleoperation, a move, a
                trajectory...) drives one of them.
        """
        owners = self.leases.owners()
        with self._lock:
            older = [
                other
                for other, lease in self._channels.items()
                if other is not channel and any(owners.get(m) is lease for m in motors)
            ]
        for other in older:
            if channel.client and other.client == channel.client:
                other.close("the client reconnected")
        lease = Lease(
            "teleop",
            client=channel.address,
            holder=channel,
            stop=f"teleop.stop from its client, or {STOP_ALL}",
        )
        self.leases.take(lease, motors)
        with self._lock:
            self._channels[channel] = lease

    def release(self, channel: TeleopChannel) -> None:
        """Free the motors of ``channel``."""
        with self._lock:
            lease = self._channels.pop(channel, None)
        if lease is not None:
            self.leases.release(lease)

    def states(self) -> dict[str, str]:
        """Motor -> the state of the session teleoperating it (``following``, ``held``...)."""
        with self._lock:
            leases = {lease: channel for channel, lease in self._channels.items()}
        return {
            motor: channel.session.state if channel.session is not None else "idle"
            for motor, lease in self.leases.owners().items()
            if (channel := leases.get(lease)) is not None
        }

    def close(self, reason: str = "the server stops") -> None:
        """Stop every session (server shutdown, the robot-wide stop)."""
        with self._lock:
            channels = list(self._channels)
        for channel in channels:
            channel.close(reason)


class TeleopChannel:
    """The teleoperation of one WebSocket connection.

    Args:
        robot: the robot served.
        registry: the motors' owners (shared by the connections).
        notify: sends a message to this connection (thread-safe; may drop it once closed).
        address: where the connection comes from (the lease's client: ``teleop from ADDR``).
    """

    def __init__(
        self, robot: Robot, registry: TeleopRegistry, notify: Notify, address: str = ""
    ) -> None:
        self.robot = robot
        self.registry = registry
        self.notify = notify
        self.address = address
        self.session: GoalStream | None = None
        self.client = ""
        """The id the client gave (a reconnecting client takes its motors back)."""
        self._lock = threading.Lock()
        self._wake = threading.Event()
        self._newest: dict[str, float] | None = None
        self._close_reason = "the teleoperation ended"
        self._worker: Worker | None = None

    # -- messages (called on the event loop: cheap, never blocks on the bus) --------------------

    def handle(self, message: Mapping[str, Any]) -> dict[str, Any] | None:
        """Act on a typed message; returns the answer to send, if any.

        Raises:
            ApiError: an unknown type, a bad field, a motor already teleoperated.
        """
        kind = message.get("type")
        if kind == "teleop.goals":
            self._goals(message.get("positions"))
            return None
        if kind == "teleop.start":
            return self._start(message)
        if kind == "teleop.hold":
            reason = message.get("reason")
            session = self.session
            if session is not None:
                session.hold(str(reason)[:200] if reason else "the client holds")
            return None
        if kind == "teleop.stop":
            self.close("the client stopped")
            return {"type": "teleop.stopped"}
        raise ApiError("invalid", f"unknown message type {kind!r}", tip=TIP)

    def _start(self, message: Mapping[str, Any]) -> dict[str, Any]:
        names = [m.name for m in self.robot.motors]
        motors = message.get("motors")
        if motors is None:
            motors = names
        if not (isinstance(motors, list) and motors and all(isinstance(m, str) for m in motors)):
            raise ApiError("invalid", "motors must be a list of names (or null: all)", tip=TIP)
        unknown = [m for m in motors if m not in names]
        if unknown:
            known = ", ".join(names)
            raise ApiError("not_found", f"no motor {', '.join(unknown)} (motors: {known})")
        watchdog = _number(message, "watchdog_s", DEFAULT_WATCHDOG_S, *WATCHDOG_RANGE_S)
        ramp = message.get("ramp_s")
        ramp_s = None if ramp is None else _number(message, "ramp_s", 0.0, 0.0, MAX_RAMP_S)
        client = message.get("client")
        if client is not None and not isinstance(client, str):
            raise ApiError("invalid", "client must be a text id", tip=TIP)
        self.close("a new teleoperation starts")
        self.client = (client or "")[:100]
        self.registry.claim(self, list(motors))
        session = GoalStream(
            self.robot, motors, ramp_s=ramp_s, watchdog_s=watchdog, on_change=self._changed
        )
        with self._lock:
            self.session = session
            self._newest = None
        # One worker per session: the last one may still be finishing.
        self._worker = Worker("teleop channel", lambda stopping: self._work(session, stopping))
        self._worker.start()
        return {
            "type": "teleop.started",
            "motors": list(motors),
            "positions": session.positions(),
            "watchdog_s": watchdog,
        }

    def _goals(self, positions: Any) -> None:
        session = self.session
        if session is None or session.state == "stopped":
            raise ApiError("conflict", "no teleoperation: send teleop.start first", tip=TIP)
        if not isinstance(positions, Mapping) or not positions:
            raise ApiError("invalid", "positions must be an object {motor: degrees}", tip=TIP)
        goals: dict[str, float] = {}
        followed = set(session.motor_names)
        for name, value in positions.items():
            if name not in followed:
                raise ApiError(
                    "not_found",
                    f"{name!r} is not teleoperated (motors: {', '.join(session.motor_names)})",
                )
            goals[name] = checks.number(value, name)  # ArgumentError: an error frame
        with self._lock:
            self._newest = goals if self._newest is None else {**self._newest, **goals}
        self._wake.set()

    # -- the worker ------------------------------------------------------------------------------

    def _work(self, session: GoalStream, stopping: threading.Event) -> None:
        """Pushes the newest goals into ``session`` until closed (an error is the worker's:
        logged once; the session stops holding either way)."""
        try:
            session.start()
            while not stopping.is_set():
                self._wake.wait(TICK_S)
                self._wake.clear()
                with self._lock:
                    goals, self._newest = self._newest, None
                if goals:
                    session.push(goals)
                elif session.expired():
                    session.hold(f"no goals for {session.watchdog_s:g} s: link lost?")
        finally:
            session.stop(self._close_reason)

    def _changed(self, change: GoalStreamChange) -> None:
        self.notify({"type": "teleop.state", "state": change.state, "reason": change.reason})

    def close(self, reason: str) -> None:
        """End the session: the motors hold where they are (stiff). Blocks for the worker."""
        self._close_reason = reason
        worker = self._worker
        if worker is not None:
            worker.request_stop()
            self._wake.set()
            worker.close(2.0)  # joins (but from its own thread)
        self._worker = None
        session = self.session
        if session is not None and session.state != "stopped":
            session.stop(reason)
        self.registry.release(self)


def _number(message: Mapping[str, Any], key: str, default: float, low: float, high: float) -> float:
    value = message.get(key, default)
    if value is None:
        value = default
    return checks.in_range(value, low, high, key, "s")
