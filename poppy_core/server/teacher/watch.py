"""``FleetWatch``: every robot of a Zenoh fleet as the teacher's page shows it, kept live.

Fed by the fleet's Zenoh subscriptions (``Fleet.on_presence``, ``on_state``, ``on_health``): a
robot that comes gets a card, described once (creature, moves, primitives, cameras) by a worker
thread, never in Zenoh's callback; its health (every second) says whether it is well and what it
is doing, its state messages give its hottest motor. A robot that leaves keeps its card, marked
gone, until it comes back. ``version`` grows with every change, so a page's stream sends only
news.
"""

from __future__ import annotations

import logging
import math
import threading
import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from poppy_core.schedule import Worker

if TYPE_CHECKING:
    from poppy_core.remote.zenoh_fleet import Fleet
    from poppy_core.zenoh_wire import RobotState

logger = logging.getLogger(__name__)

DESCRIBE_PERIOD_S = 0.5
"""How often the worker looks for robots to describe."""
REDESCRIBE_S = 10.0
"""A description is asked again after this long (a move recorded since shows up)."""
STALE_S = 2.0
"""No state for this long: the card says the robot's state stopped coming."""


@dataclass
class Card:
    """What the page shows of one robot."""

    name: str
    alive: bool = True
    described: dict[str, Any] = field(default_factory=dict)
    described_at: float = -math.inf
    health: dict[str, Any] | None = None
    temperature: float | None = None
    hottest: str | None = None
    state_at: float | None = None
    """When the last state message arrived (monotonic)."""

    def as_dict(self, now: float) -> dict[str, Any]:
        """The card as JSON: who, how it is, what it does, what it can do."""
        described, health = self.described, self.health or {}
        state_age = None if self.state_at is None else round(now - self.state_at, 1)
        return {
            "name": self.name,
            "alive": self.alive,
            "described": bool(described),
            "creature": str(described.get("creature", "")),
            "motors": len(described.get("motors", [])),
            "token": bool(described.get("token", False)),
            "health": _verdict(self.alive, health, state_age),
            "ok": self.alive
            and bool(health.get("ok", False))
            and state_age is not None
            and state_age < STALE_S,
            "offline": list(health.get("offline", [])),
            "state_hz": health.get("state_hz"),
            "temperature": self.temperature,
            "hottest": self.hottest,
            "running": list(health.get("running", [])),
            "playing": list(health.get("playing", [])),
            "moves": list(described.get("moves", [])),
            "primitives": list(described.get("primitives", [])),
            "cameras": list(described.get("cameras", [])),
            "no_camera": str(described.get("no_camera", "")),
        }


def _verdict(alive: bool, health: dict[str, Any], state_age: float | None) -> str:
    """The card's health line: ok, what is offline, or why nothing is known."""
    if not alive:
        return "left the network"
    if not health:
        return "waiting for its health"
    if state_age is None or state_age >= STALE_S:
        return "no state for a while" if state_age is not None else "waiting for its state"
    if health.get("ok"):
        return "ok"
    if health.get("offline"):
        return "offline: " + ", ".join(health["offline"])
    return "bus trouble"


class FleetWatch:
    """The robots of ``fleet``, one ``Card`` each, kept from its Zenoh subscriptions.

    Args:
        fleet: the fleet (its session stays the caller's; ``close`` only stops the worker).

    The subscriptions are made at once; ``start`` starts describing the robots.
    """

    def __init__(self, fleet: Fleet) -> None:
        self.fleet = fleet
        self.version = 0
        self._cards: dict[str, Card] = {}
        self._lock = threading.Lock()
        self._worker = Worker.periodic("teacher-describe", 1.0 / DESCRIBE_PERIOD_S, self._tick)
        fleet.on_presence(self._presence)
        fleet.on_health(self._health)
        fleet.on_state(self._state)

    def start(self) -> None:
        """Describe the robots as they come (a worker thread)."""
        self._worker.start()

    def snapshot(self) -> list[dict[str, Any]]:
        """Every card, in name order."""
        now = time.monotonic()
        with self._lock:
            return [self._cards[n].as_dict(now) for n in sorted(self._cards)]

    def alive(self) -> list[str]:
        """The robots here now, in name order."""
        with self._lock:
            return sorted(n for n, card in self._cards.items() if card.alive)

    def close(self) -> None:
        """Stop describing (the subscriptions end with the fleet)."""
        self._worker.close()

    # -- from Zenoh's threads: short ------------------------------------------------------------

    def _card(self, name: str) -> Card:
        card = self._cards.get(name)
        if card is None:
            card = self._cards[name] = Card(name)
        return card

    def _presence(self, name: str, alive: bool) -> None:
        with self._lock:
            card = self._card(name)
            card.alive = alive
            if not alive:
                card.state_at = None
                card.described_at = -math.inf  # described again when it is back
            self.version += 1

    def _health(self, name: str, health: dict[str, Any]) -> None:
        with self._lock:
            self._card(name).health = health
            self.version += 1

    def _state(self, name: str, state: RobotState) -> None:
        hottest, temperature = None, None
        for motor, values in state.motors.items():
            value = values.get("present_temperature")
            if value is not None and (temperature is None or value > temperature):
                hottest, temperature = motor, value
        with self._lock:
            card = self._card(name)
            card.state_at = time.monotonic()
            if (card.hottest, card.temperature) != (hottest, temperature):
                card.hottest, card.temperature = hottest, temperature
                self.version += 1

    # -- the worker: descriptions ---------------------------------------------------------------

    def _tick(self, now: float) -> None:
        with self._lock:
            wanted = [
                n
                for n, card in self._cards.items()
                if card.alive and now - card.described_at >= REDESCRIBE_S
            ]
        if not wanted:
            return
        found = self.fleet.describe(wanted)
        with self._lock:
            for name in wanted:
                card = self._card(name)
                described = found.get(name)
                if described is None:
                    continue  # not answered yet: asked again at the next tick
                card.described, card.described_at = described, now
                if card.health is None and isinstance(described.get("health"), dict):
                    card.health = described["health"]
            self.version += 1
