"""``Robot``: named motors and groups over one or more buses, their sync loops and gotos.

Build one with ``poppy_core.from_config``, ``from_profile`` or ``autodetect``; a Robot owns
its buses, threads and (with ``sim=True``) emulators, and ``close()`` stops them all. pypot's
names for its groups and primitives are in ``robot_pypot``, its sync loops and ports in
``robot_syncs``, pypot's V-REP calls in ``vrep_names``; ``motors_of`` resolves specs with
``motor_spec``.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable, Iterator, Mapping, Sequence
from typing import TYPE_CHECKING, Any

from poppy_core.bus import DxlBus
from poppy_core.errors import ConfigError, RobotClosedError, UnknownGroupError, UnknownMotorError
from poppy_core.robot.goto import GotoHandle, GotoRunner
from poppy_core.robot.group import MotorGroup, degrees
from poppy_core.robot.motor import Motor
from poppy_core.robot.motor_link import link_of
from poppy_core.robot.motor_spec import MotorSpec, NamedMotor, resolve
from poppy_core.robot.robot_pypot import Behaviour, PypotRobotMixin
from poppy_core.robot.robot_syncs import SyncLoops
from poppy_core.robot.sync import BusSync
from poppy_core.robot.vrep_names import VrepNames
from poppy_core.schedule import close_all

if TYPE_CHECKING:
    from poppy_core.robot.config import RobotConfig
    from poppy_core.sensors import Sensor, SensorHealth

logger = logging.getLogger(__name__)

__all__ = ["Behaviour", "MotorSpec", "NamedMotor", "Robot"]


class Robot(PypotRobotMixin, SyncLoops, VrepNames):
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
        sensors: name -> sensor (cameras, marker detectors), reachable as ``robot.<name>``.
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
        sensors: Mapping[str, Sensor] | None = None,
    ) -> None:
        self._motors = list(motors)
        self._by_name = {m.name: m for m in self._motors}
        if len(self._by_name) != len(self._motors):
            raise ConfigError("two motors have the same name", field="motors")
        self._groups: dict[str, MotorGroup] = {}
        for name, members in (groups or {}).items():
            missing = [n for n in members if n not in self._by_name]
            if missing:
                raise ConfigError(
                    f"group {name!r} names unknown motors: {', '.join(missing)}",
                    field=f"motorgroups.{name}",
                )
            self._groups[name] = MotorGroup(name, (self._by_name[n] for n in members))
        self._sensors: dict[str, Sensor] = dict(sensors or {})
        clash = sorted(set(self._sensors) & {*self._by_name, *self._groups})
        if clash:
            raise ConfigError(
                f"sensor {clash[0]!r} has the name of a motor or group", field=f"sensors.{clash[0]}"
            )
        for name in [*self._by_name, *self._groups, *self._sensors]:
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
            link_of(motor).runner = self._runner
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
        sensors = self.__dict__.get("_sensors", {})
        if name in sensors:
            return sensors[name]
        extensions = self.__dict__.get("extensions", {})
        if name in extensions:
            return extensions[name]
        raise AttributeError(f"robot has no motor, group, sensor or attribute {name!r}")

    def __dir__(self) -> list[str]:
        names = {*self._by_name, *self._groups, *self._sensors, *self.extensions}
        return sorted({*super().__dir__(), *names})

    def __repr__(self) -> str:
        return f"<Robot motors={[m.name for m in self._motors]}>"

    @property
    def motors(self) -> list[Motor]:
        """Every motor, in config order."""
        return list(self._motors)

    def motor(self, name: str) -> Motor:
        """The motor called ``name`` (typed access).

        Raises:
            UnknownMotorError: no motor of that name (the known ones are listed).
        """
        try:
            return self._by_name[name]
        except (KeyError, TypeError):
            known = list(self._by_name)
            raise UnknownMotorError(
                f"no motor {name!r} (motors: {', '.join(known)})", motor=str(name), known=known
            ) from None

    def motors_of(self, spec: MotorSpec | None) -> list[Motor]:
        """The motors a spec names, each once, in order: every motor for None, a motor or group
        name, a motor, or a list of those (``"head_z"`` is one name, not five letters).

        Raises:
            UnknownMotorError: a name that is neither a motor nor a group (known ones listed).
            ArgumentError: an item that is neither a name nor a motor.
        """
        return resolve(spec, self._by_name, self._groups)

    @property
    def sensors(self) -> list[Sensor]:
        """Every sensor (cameras, marker detectors), in config order (pypot's ``sensors``)."""
        return list(self._sensors.values())

    def sensor(self, name: str) -> Sensor:
        """The sensor called ``name`` (typed access).

        Raises:
            ConfigError: no such sensor.
        """
        try:
            return self._sensors[name]
        except KeyError:
            known = ", ".join(self._sensors) or "none"
            raise ConfigError(f"no sensor {name!r} (sensors: {known})", field=name) from None

    def sensor_health(self) -> dict[str, SensorHealth]:
        """Sensor name -> its health (connected, rate, errors), as the buses report theirs."""
        return {name: sensor.health() for name, sensor in self._sensors.items()}

    def group(self, name: str) -> list[Motor]:
        """The motors of group ``name`` (typed access)."""
        try:
            return list(self._groups[name])
        except KeyError:
            known = list(self._groups)
            raise UnknownGroupError(
                f"no group {name!r} (groups: {', '.join(known) or 'none'})",
                motor=str(name),
                known=known,
            ) from None

    # -- extensions: attached objects ---------------------------------------------------------

    def attach(self, name: str, obj: object) -> None:
        """Make ``obj`` reachable as ``robot.<name>`` (replacing what was attached there).

        Raises:
            ConfigError: ``name`` is not an identifier, starts with ``_``, or is a motor, a group
                or a Robot attribute.
        """
        if not name.isidentifier() or name.startswith("_"):
            raise ConfigError(f"{name!r} cannot be an attribute name", field=name, value=name)
        taken = (*self._by_name, *self._groups, *self._sensors, *self.__dict__)
        if name in taken or hasattr(type(self), name):
            raise ConfigError(
                f"{name!r} is already a motor, group or attribute of the robot", field=name
            )
        self.extensions[name] = obj

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
        control: str | None = None,
        wait: bool = False,
    ) -> GotoHandle:
        """Move several motors so that they all arrive together.

        Args:
            position_for_motors: motor name -> target in degrees (user frame).
            duration: seconds the motion lasts.
            control: ``"minjerk"`` or ``"dummy"`` (see ``Motor.goto_position``); None: each
                motor's ``goto_behavior``.
            wait: block until every motor arrived.

        Returns:
            The handle of the motion.

        Raises:
            UnknownMotorError: an unknown motor name.
            ArgumentError: a target that is not a finite number, a negative duration, an unknown
                control.
            RobotClosedError: the robot is closed.
        """
        if self._closed:
            raise RobotClosedError("the robot is closed: no more motions")
        targets = {self.motor(n): degrees(n, pos) for n, pos in position_for_motors.items()}
        handle = self._runner.start(targets, duration, control)
        if wait:
            handle.wait()
        return handle

    # -- config and lifetime -----------------------------------------------------------------

    def to_robot_config(self) -> RobotConfig:
        """``to_config`` as a validated ``RobotConfig`` (profile header kept).

        The limits are written in the motor frame, as configs hold them.

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
                entry["angle_limit"] = list(motor.config_limits())
        return type(self.config).from_dict(data, source="robot")

    @property
    def closed(self) -> bool:
        """True once ``close`` ran."""
        return self._closed

    def close(self) -> None:
        """Close sensors, stop gotos and loops (sending pending writes), close buses, stop owned
        emulators and the simulation: every part, whatever fails first (each failure is logged
        once at WARNING and the next part is closed)."""
        with self._close_lock:
            if self._closed:
                return
            self._closed = True
        close_all(self._closing_steps(), logger, "the robot")

    def _closing_steps(self) -> Iterator[tuple[str, Callable[[], object]]]:
        for callback in reversed(self._closers):
            yield repr(callback), callback
        for sensor in reversed(self._sensors.values()):  # detectors before their cameras
            yield f"sensor {sensor.name}", sensor.close
        yield "the gotos", self._runner.close
        for sync in self._syncs:
            yield f"the sync loop of {sync.controller}", sync.stop
        for motor in self._motors:  # after the loops: only callers' writes are refused now
            yield f"motor {motor.name}", link_of(motor).mark_closed
        for name, bus in self.buses.items():
            yield f"bus {name}", bus.close
        for name, server in self.emulators.items():
            yield f"the emulator of {name}", server.stop
        if self.simulation is not None:
            yield "the simulation", self.simulation.close

    def __enter__(self) -> Robot:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
