"""What the sync loops report: per-loop statistics, per-bus statistics and the bus's health."""

from __future__ import annotations

from dataclasses import dataclass, field

PYPOT_PLACEHOLDER = "my_dxl_controller"
"""The controller name of pypot's configs (the Ergo Jr's), which says nothing of the bus: kept in
config files and ``robot._controllers``, where pypot's API reads it, and not shown to people."""


def bus_label(controller: str, port: str) -> str:
    """The name people are shown for a bus: the port's last part (``ttyUSB0``, ``ttyACM0``,
    ``emu://1``) for pypot's placeholder controller name, else the controller's own name
    (``upper_body_controller``)."""
    if controller != PYPOT_PLACEHOLDER or not port:
        return controller
    if "://" in port:
        return port
    return port.replace("\\", "/").rstrip("/").rsplit("/", 1)[-1] or port


@dataclass(frozen=True)
class LoopStats:
    """What one loop did: target and measured rate, runs, skipped periods, errors."""

    name: str
    target_hz: float
    measured_hz: float
    runs: int
    missed_periods: int
    errors: int
    last_duration_s: float


@dataclass(frozen=True)
class SyncStats:
    """One bus's loops, its motors' health and its bus counters."""

    controller: str
    port: str
    running: bool
    loops: dict[str, LoopStats]
    motor_errors: dict[str, int]
    offline: list[str]
    bus: dict[str, int] = field(default_factory=dict)

    def as_dict(self) -> dict[str, object]:
        """Plain data (for ``--json``)."""
        return {
            "controller": self.controller,
            "port": self.port,
            "running": self.running,
            "loops": {name: vars(loop) for name, loop in self.loops.items()},
            "motor_errors": dict(self.motor_errors),
            "offline": list(self.offline),
            "bus": dict(self.bus),
        }


@dataclass(frozen=True)
class BusHealth:
    """Is one bus well? ``Robot.health()`` gives one per controller.

    Attributes:
        controller: the controller's name.
        port: its port.
        connected: False while the port is lost (adapter unplugged, emulator gone); the sync
            thread reopens it with backoff.
        running: the sync thread is alive.
        down_s: seconds since the port was lost (0 while connected).
        losses: times the port was lost since the robot started.
        loop_hz: loop name -> rate measured now (0 for a loop that stopped running).
        target_hz: loop name -> rate asked for.
        loop_errors: failed loop runs since the start.
        timeouts: bus transactions that got no reply.
        retries: bus attempts repeated after a timeout or a corrupt reply.
        corrupt_packets: replies dropped as corrupt.
        motor_errors: replies whose error bits refused an instruction.
        offline: motors that do not answer (retried once a second).
    """

    controller: str
    port: str
    connected: bool
    running: bool
    down_s: float
    losses: int
    loop_hz: dict[str, float]
    target_hz: dict[str, float]
    loop_errors: int
    timeouts: int
    retries: int
    corrupt_packets: int
    motor_errors: int
    offline: list[str]

    @property
    def ok(self) -> bool:
        """Connected, running, and every motor answering."""
        return self.connected and self.running and not self.offline

    @property
    def label(self) -> str:
        """The bus's name for people (``bus_label``): ``ttyUSB0`` for ``my_dxl_controller``."""
        return bus_label(self.controller, self.port)

    def as_dict(self) -> dict[str, object]:
        """Plain data (for ``--json`` and the REST API)."""
        data = dict(vars(self))
        data["ok"] = self.ok
        data["label"] = self.label
        data["loop_hz"] = {name: round(hz, 2) for name, hz in self.loop_hz.items()}
        data["down_s"] = round(self.down_s, 3)
        return data
