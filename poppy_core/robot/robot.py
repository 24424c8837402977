"""``Robot``: named motors and groups over one or more buses, their sync loops and gotos.

Build one with ``poppy_core.robot.from_config``, ``from_profile`` or ``autodetect``; a Robot owns
its buses, threads and (with ``sim=True``) emulators, and ``close()`` stops them all.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable, Mapping, Sequence
from types import TracebackType
from typing import TYPE_CHECKING, Any, Protocol

from poppy_core.bus import DxlBus
from poppy_core.errors import ConfigError
from poppy_core.robot.goto import GotoHandle, GotoRunner
from poppy_core.robot.health import BusHealth, SyncStats
from poppy_core.robot.motor import Motor
from poppy_core.robot.sync import BusSync

if TYPE_CHECKING:
    from poppy_core.robot.config import RobotConfig

logger = logging.getLogger(__name__)


class Behaviour(Protocol):
    """What ``attach_primitive`` needs of a primitive (``poppy_core.motion.Primitive``)."""

    def is_alive(self) -> bool:
        """True while it runs."""
        ...


class Robot:
    """Motors by name (``robot.m1``), groups by name (``robot.base``, a list of Motor).

    Args:
        motors: the motors, in order.
        groups: group name -> motor names (already flattened).
        syncs: one ``BusSync`` per bus (started by ``start_sync``).
        buses: controller name -> open bus (closed by ``close``).
        config: the config it was built from (``to_config`` starts from it).
        emulators: controller name -> emulator server this robot started (``sim=True``).
        goto_runner: runs the gotos; one at 50 Hz when None.
        simulation: the MuJoCo world behind the emulators (``sim="mujoco"``), stopped by close.
    """

    def __init__(
        self,
        motors: Sequence[Motor],
        *,
        groups: Mapping[str, Sequence[str]] | None = None,
        syncs: Sequence[BusSync] = (),
        buses: Mapping[str, DxlBus] | None = None,
        config: RobotConfig | None = None,
        emulators: Mapping[str, Any] | None = None,
        goto_runner: GotoRunner | None = None,
        simulation: Any = None,
    ) -> None:
        self._motors = list(motors)
        self._by_name = {m.name: m for m in self._motors}
        if len(self._by_name) != len(self._motors):
            raise ConfigError("two motors have the same name", field="motors")
        self._groups: dict[str, list[Motor]] = {}
        for name, members in (groups or {}).items():
            missing = [n for n in members if n not in self._by_name]
            if missing:
                raise ConfigError(
                    f"group {name!r} names unknown motors: {', '.join(missing)}",
                    field=f"motorgroups.{name}",
                )
            self._groups[name] = [self._by_name[n] for n in members]
        for name in [*self._by_name, *self._groups]:
            if hasattr(type(self), name):
                logger.warning("%r hides a Robot attribute: use robot.motor()/group()", name)
        self._syncs = list(syncs)
        self.buses: dict[str, DxlBus] = dict(buses or {})
        self.config = config
        self.emulators: dict[str, Any] = dict(emulators or {})
        """Controller name -> ``EmulatorServer`` (its ``.bus`` is the ``VirtualBus``)."""
        self.simulation: Any = simulation
        """The simulation handle (``poppy_core.sim.world.Simulation``) with MuJoCo, else None:
        ``reset()``, ``get_object_position``, ``add_object``, ``colliding``, ``render``..."""
        self._runner = goto_runner if goto_runner is not None else GotoRunner(name="goto robot")
        for motor in self._motors:
            motor.attach_runner(self._runner)
        self.extensions: dict[str, object] = {}
        """Named objects reachable as ``robot.<name>`` (attached primitives, their manager)."""
        self._primitive_names: list[str] = []
        self._closers: list[Callable[[], None]] = []
        self._close_lock = threading.Lock()
        self._closed = False

    # -- access ------------------------------------------------------------------------------

    def __getattr__(self, name: str) -> Any:
        # Only called when normal lookup fails: motors and groups by name.
        if name.startswith("_"):
            raise AttributeError(name)
        motors = self.__dict__.get("_by_name", {})
        if name in motors:
            return motors[name]
        groups = self.__dict__.get("_groups", {})
        if name in groups:
            return groups[name]
        extensions = self.__dict__.get("extensions", {})
        if name in extensions:
            return extensions[name]
        raise AttributeError(f"robot has no motor, group or attribute {name!r}")

    def __dir__(self) -> list[str]:
        return sorted({*super().__dir__(), *self._by_name, *self._groups, *self.extensions})

    def __repr__(self) -> str:
        return f"<Robot motors={[m.name for m in self._motors]}>"

    @property
    def motors(self) -> list[Motor]:
        """Every motor, in config order."""
        return list(self._motors)

    @property
    def motorgroups(self) -> dict[str, list[Motor]]:
        """Group name -> its motors."""
        return {name: list(members) for name, members in self._groups.items()}

    def motor(self, name: str) -> Motor:
        """The motor called ``name`` (typed access)."""
        try:
            return self._by_name[name]
        except KeyError:
            known = ", ".join(self._by_name)
            raise ConfigError(f"no motor {name!r} (motors: {known})", field=name) from None

    def group(self, name: str) -> list[Motor]:
        """The motors of group ``name`` (typed access)."""
        try:
            return list(self._groups[name])
        except KeyError:
            known = ", ".join(self._groups) or "none"
            raise ConfigError(f"no group {name!r} (groups: {known})", field=name) from None

    # -- extensions: attached objects ---------------------------------------------------------

    def attach(self, name: str, obj: object) -> None:
        """Make ``obj`` reachable as ``robot.<name>`` (replacing what was attached there).

        Raises:
            ConfigError: ``name`` is not an identifier, starts with ``_``, or is a motor, a group
                or a Robot attribute.
        """
        if not name.isidentifier() or name.startswith("_"):
            raise ConfigError(f"{name!r} cannot be an attribute name", field=name, value=name)
        taken = (*self._by_name, *self._groups, *self.__dict__)
        if name in taken or hasattr(type(self), name):
            raise ConfigError(
                f"{name!r} is already a motor, group or attribute of the robot", field=name
            )
        self.extensions[name] = obj

    def attach_primitive(self, primitive: Behaviour, name: str) -> None:
        """Attach a primitive as ``robot.<name>`` and list it in ``primitives`` (pypot's order).

        Raises:
            ConfigError: see ``attach``.
        """
        self.attach(name, primitive)
        if name not in self._primitive_names:
            self._primitive_names.append(name)

    @property
    def primitive_names(self) -> list[str]:
        """Names of the attached primitives, in attach order."""
        return [n for n in self._primitive_names if n in self.extensions]

    @property
    def primitives(self) -> list[Any]:
        """The attached primitives, in attach order."""
        return [self.extensions[n] for n in self.primitive_names]

    @property
    def active_primitives(self) -> list[Any]:
        """The attached primitives that are running (or paused)."""
        return [p for p in self.primitives if p.is_alive()]

    def on_close(self, callback: Callable[[], None]) -> None:
        """Run ``callback`` first thing in ``close`` (e.g. to stop the primitives' threads)."""
        self._closers.append(callback)

    # -- whole-robot commands --------------------------------------------------------------------

    @property
    def compliant(self) -> bool:
        """True when every motor is compliant; setting it sets every motor."""
        return all(m.compliant for m in self._motors)

    @compliant.setter
    def compliant(self, value: bool) -> None:
        for motor in self._motors:
            motor.compliant = value

    def power_up(self) -> None:
        """Stiffen every motor and give it back its full torque limit."""
        for motor in self._motors:
            motor.compliant = False
            if motor.model.has_torque_limit:
                motor.torque_limit = 100.0

    def goto_position(
        self,
        position_for_motors: Mapping[str, float],
        duration: float,
        control: str = "minjerk",
        wait: bool = False,
    ) -> GotoHandle:
        """Move several motors so that they all arrive together.

        Args:
            position_for_motors: motor name -> target in degrees (user frame).
            duration: seconds the motion lasts.
            control: ``"minjerk"`` or ``"dummy"`` (see ``Motor.goto_position``).
            wait: block until every motor arrived.

        Returns:
            The handle of the motion.

        Raises:
            ConfigError: an unknown motor name.
        """
        targets = {self.motor(name): float(pos) for name, pos in position_for_motors.items()}
        handle = self._runner.start(targets, duration, control)
        if wait:
            handle.wait()
        return handle

    # -- loops -------------------------------------------------------------------------------

    def start_sync(self) -> None:
        """Start the sync loops (``from_config`` does it)."""
        for sync in self._syncs:
            sync.start()

    def stop_sync(self) -> None:
        """Stop the sync loops (pending writes are sent first)."""
        for sync in self._syncs:
            sync.stop()

    def sync_stats(self) -> dict[str, SyncStats]:
        """Controller name -> measured loop rates, error counts and offline motors."""
        return {sync.controller: sync.stats() for sync in self._syncs}

    def health(self) -> dict[str, BusHealth]:
        """Controller name -> its bus's health: connected, loop rates, errors, offline motors."""
        return {sync.controller: sync.health() for sync in self._syncs}

    # -- config and lifetime -----------------------------------------------------------------

    def to_config(self) -> RobotConfig:
        """The robot's config with the motors' present orientation, offset and angle limits.

        Raises:
            ConfigError: the robot was not built from a config.
        """
        if self.config is None:
            raise ConfigError("this robot was built by hand: it has no config to export")
        data = self.config.to_dict()
        for motor in self._motors:
            entry = data["motors"].get(motor.name)
            if entry is not None:
                entry["orientation"] = motor.orientation
                entry["offset"] = motor.offset
                entry["angle_limit"] = list(motor.angle_limit)
        return type(self.config).from_dict(data, source="robot")

    @property
    def closed(self) -> bool:
        """True once ``close`` ran."""
        return self._closed

    def close(self) -> None:
        """Stop gotos and loops (sending pending writes), close buses, stop owned emulators."""
        with self._close_lock:
            if self._closed:
                return
            self._closed = True
        for callback in reversed(self._closers):
            try:
                callback()
            except Exception:
                logger.exception("closing the robot: %r failed", callback)
        self._runner.close()
        for sync in self._syncs:
            sync.stop()
        for name, bus in self.buses.items():
            try:
                bus.close()
            except OSError as exc:
                logger.warning("closing bus %s: %s", name, exc)
        for server in self.emulators.values():
            server.stop()
        if self.simulation is not None:
            self.simulation.close()

    def __enter__(self) -> Robot:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.close()
