"""Teleoperation over Zenoh: ``ZenohLeader`` (a served robot's state stream read as a leader) and
``ZenohFollower`` (a served robot driven through its goal stream), for ``Teleoperation``.

The leader's watchdog: when no state message came for ``WATCHDOG_S`` (0.25 s), reading the
leader fails, so the teleoperation holds the follower where it is and ramps again once the
state flows. A follower whose goals stop arriving keeps its last goal: it holds by itself.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator, Mapping, Sequence
from contextlib import contextmanager
from typing import TYPE_CHECKING, Any

from poppy_core import zenoh_wire
from poppy_core.errors import CommunicationError, ConfigError
from poppy_core.remote.client import DEFAULT_TIMEOUT_S, path_of
from poppy_core.remote.zenoh_client import ZenohClient, client_settings

if TYPE_CHECKING:
    import zenoh

WATCHDOG_S = 0.25
"""A leader silent this long is lost: the follower holds."""
RAMP_S = 0.5
"""The follower's ramp from where it is to the leader, at the start and after a hold."""


class _StateWatch:
    """The latest state message of one robot, and when it came."""

    def __init__(self, session: zenoh.Session, name: str) -> None:
        self.name = name
        self.state: zenoh_wire.RobotState | None = None
        self.received = 0.0
        self.arrived = threading.Event()
        self._subscriber = session.declare_subscriber(
            zenoh_wire.robot_key(name, "state"), self._received
        )

    def _received(self, sample: zenoh.Sample) -> None:
        try:
            self.state = zenoh_wire.unpack_state(sample.payload.to_bytes())
        except ConfigError:
            return
        self.received = time.monotonic()
        self.arrived.set()

    def positions(self) -> dict[str, float]:
        state = self.state
        if state is None:
            return {}
        return {
            n: float(v["present_position"])
            for n, v in state.motors.items()
            if v["present_position"] is not None
        }

    def close(self) -> None:
        self._subscriber.undeclare()  # type: ignore[no-untyped-call]


def _open(
    name: str, token: str | None, settings: zenoh_wire.ZenohSettings | None, timeout_s: float
) -> tuple[ZenohClient, _StateWatch, list[str]]:
    client = ZenohClient(name, token, timeout_s, settings=settings or client_settings())
    try:
        # subscribed first: the subscription reaches the robot while its motors are asked
        watch = _StateWatch(client.session, name)
        try:
            motors = [str(m["name"]) for m in client.get(path_of("motors"))]
            if not watch.arrived.wait(timeout_s):
                raise CommunicationError(
                    f"zenoh:{name}: no state message within {timeout_s:g} s", port=f"zenoh:{name}"
                )
        except BaseException:
            watch.close()
            raise
    except BaseException:
        client.close()
        raise
    return client, watch, motors


class ZenohLeaderMotor:
    """A leader motor: its position from the state stream, its compliance set over ``api``."""

    def __init__(self, leader: ZenohLeader, name: str) -> None:
        self._leader = leader
        self.name = name

    @property
    def present_position(self) -> float:
        """The last position streamed (degrees)."""
        return self._leader.watch.positions()[self.name]

    @property
    def online(self) -> bool:
        """False when the robot says the motor does not answer."""
        state = self._leader.watch.state
        return state is not None and bool(state.motors[self.name]["online"])

    @property
    def compliant(self) -> bool:
        """As streamed."""
        state = self._leader.watch.state
        return state is not None and bool(state.motors[self.name]["compliant"])

    @compliant.setter
    def compliant(self, value: bool) -> None:
        path = path_of("motors", self.name, "registers", "compliant")
        self._leader.client.request("PUT", path, {"value": bool(value)})


class ZenohLeader:
    """A robot served with ``poppy serve --zenoh`` as a teleoperation leader (read-only but
    for its compliance), ``Robot``'s names that ``Teleoperation`` uses.

    Raises:
        CommunicationError: the robot is not there or streams no state.
    """

    def __init__(
        self,
        name: str,
        token: str | None = None,
        *,
        settings: zenoh_wire.ZenohSettings | None = None,
        timeout_s: float = DEFAULT_TIMEOUT_S,
    ) -> None:
        self.client, self.watch, names = _open(name, token, settings, timeout_s)
        self.url = f"zenoh:{name}"
        self.config = None
        self.motors = [ZenohLeaderMotor(self, n) for n in names]
        self._by_name = {m.name: m for m in self.motors}

    def motor(self, name: str) -> ZenohLeaderMotor:
        """The motor ``name``."""
        return self._by_name[name]

    @contextmanager
    def driving(self, name: str) -> Iterator[None]:
        """Nothing to drive: the robot's own loop reads it."""
        yield

    def run_loop(self, name: str) -> None:
        """The watchdog: fails when no state came for ``WATCHDOG_S``."""
        silent_s = time.monotonic() - self.watch.received
        if silent_s > WATCHDOG_S:
            raise CommunicationError(
                f"{self.url}: no state for {silent_s:.2f} s (link stalled)", port=self.url
            )

    def close(self) -> None:
        """Stop listening."""
        self.watch.close()
        self.client.close()


class ZenohFollower:
    """A robot served with ``poppy serve --zenoh`` as a teleoperation follower (``Follower``).

    Raises:
        CommunicationError: the robot is not there or streams no state.
    """

    def __init__(
        self,
        name: str,
        token: str | None = None,
        *,
        settings: zenoh_wire.ZenohSettings | None = None,
        timeout_s: float = DEFAULT_TIMEOUT_S,
        ramp_s: float = RAMP_S,
    ) -> None:
        import zenoh

        self.client, self.watch, self._names = _open(name, token, settings, timeout_s)
        self.url = f"zenoh:{name}"
        self.token = token
        self.ramp_s = ramp_s
        self.on_change: Any = None
        self.state = "idle"
        self._motors: list[str] = []
        self._ramp: tuple[float, dict[str, float]] | None = None
        self._publisher = self.client.session.declare_publisher(
            zenoh_wire.robot_key(name, "goals"),
            congestion_control=zenoh.CongestionControl.DROP,
            express=True,
        )

    @property
    def motor_names(self) -> list[str]:
        """Every motor of the robot."""
        return list(self._names)

    def start(self, motors: Sequence[str]) -> None:
        """Stiffen ``motors`` where they are; the first targets ramp from there."""
        self._motors = list(motors)
        for name in self._motors:
            path = path_of("motors", name, "registers", "compliant")
            self.client.request("PUT", path, {"value": False})
        self._hold_at_present()
        self._set("held", "started")

    def send(self, targets: Mapping[str, float]) -> None:
        """Publish goals, blended from where the motors were during a ramp."""
        goals = dict(targets)
        if self._ramp is not None:
            began, origin = self._ramp
            if not origin:  # the first targets after a hold: the ramp starts now
                self._ramp = began, origin = time.monotonic(), dict(self.watch.positions())
            share = min(1.0, (time.monotonic() - began) / self.ramp_s) if self.ramp_s else 1.0
            goals = {n: origin.get(n, g) + (g - origin.get(n, g)) * share for n, g in goals.items()}
            if share >= 1.0:
                self._ramp = None
                self._set("following", "ramp done")
            elif self.state != "ramping":
                self._set("ramping", "to the leader")
        client = self.client
        message = zenoh_wire.goals_message(goals, self.token, client.name, client.sender)
        self._publisher.put(message)

    def hold(self, reason: str) -> None:
        """Stop sending (the motors keep their last goal); the next targets ramp again."""
        self._hold_at_present()
        self._set("held", reason)

    def positions(self) -> dict[str, float]:
        """The present positions streamed of the motors started."""
        positions = self.watch.positions()
        return {n: positions[n] for n in self._motors if n in positions}

    def stop(self) -> None:
        """Stop sending: the motors stay stiff at their last goal."""
        self._set("stopped", "stopped")

    def close(self) -> None:
        """Undeclare and close the session."""
        self._publisher.undeclare()  # type: ignore[no-untyped-call]
        self.watch.close()
        self.client.close()

    def _hold_at_present(self) -> None:
        self._ramp = (time.monotonic(), {})

    def _set(self, state: str, reason: str) -> None:
        if state != self.state:
            self.state = state
            if self.on_change is not None:
                self.on_change(state, reason)
