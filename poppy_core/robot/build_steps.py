"""The named steps of building a robot from a config, and the clean-up when one of them fails.

``from_config`` runs them in order: :meth:`BuildSteps.start_virtual_motors` (``sim``: emulators,
MuJoCo), :meth:`BuildSteps.open_buses` (ports, presence check), :meth:`BuildSteps.prepare_motors`
(first state, return delays, EEPROM limits, torque/gains), :meth:`BuildSteps.build_sensors`,
:meth:`BuildSteps.robot`. A ``BuildSteps`` used as a context manager closes whatever it opened when
a step raises; once ``robot()`` handed them over, the robot owns them.
"""

from __future__ import annotations

import logging
from collections.abc import Iterable, Sequence
from types import TracebackType
from typing import Any

from poppy_core.bus import DxlBus, find_port, list_ports
from poppy_core.emulator import Endpoint
from poppy_core.errors import ConfigError, PortError, RegisterError, SetupError
from poppy_core.models import model_by_name
from poppy_core.robot import startup
from poppy_core.robot.config import RobotConfig
from poppy_core.robot.config_sensors import sensor_specs
from poppy_core.robot.motor import Motor
from poppy_core.robot.robot import Robot
from poppy_core.robot.startup import ReturnDelayConsent
from poppy_core.robot.sync import BusSync, loops_for
from poppy_core.robot.virtual import start_emulators, start_simulation
from poppy_core.sensors import Sensor
from poppy_core.sensors.config import (
    CameraMaker,
    ImuMaker,
    build_sensors,
    device_imu,
    dummy_camera,
    opencv_camera,
    still_imu,
)

logger = logging.getLogger(__name__)

SimMode = bool | str
SIM_MODES = ("ideal", "mujoco")


def sim_mode(sim: SimMode | None) -> str | None:
    """None (hardware), "ideal" or "mujoco" from the ``sim`` argument.

    Raises:
        ConfigError: an unknown simulation.
    """
    if sim is False or sim is None:
        return None
    if sim is True:
        return "ideal"
    if sim in SIM_MODES:
        return str(sim)
    raise ConfigError(
        f"unknown simulation {sim!r} (expected one of {', '.join(SIM_MODES)})",
        field="sim",
        value=sim,
    )


class BuildSteps:
    """A robot being built from ``config``: what is open so far, and the steps still to run.

    Args:
        config: the robot's config.
        mode: None (hardware), ``"ideal"`` or ``"mujoco"`` (see :func:`sim_mode`).
    """

    def __init__(self, config: RobotConfig, mode: str | None) -> None:
        self.config = config
        self.mode = mode
        self.simulation: Any = None
        self.emulators: dict[str, Endpoint] = {}
        self.buses: dict[str, DxlBus] = {}
        self.motors: dict[str, list[Motor]] = {}
        self.syncs: list[BusSync] = []
        self.sensors: dict[str, Sensor] = {}
        self._handed_over = False

    def __enter__(self) -> BuildSteps:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        if exc_type is not None and not self._handed_over:
            self.close()

    def close(self) -> None:
        """Close the buses, stop the emulators and the simulation opened so far."""
        for bus in self.buses.values():
            bus.close()
        for server in self.emulators.values():
            server.stop()
        if self.simulation is not None:
            self.simulation.close()

    # -- the steps ----------------------------------------------------------------------------

    def start_virtual_motors(self) -> None:
        """With ``sim``: one in-process emulator per controller (and the MuJoCo world)."""
        if self.mode is None:
            return
        if self.mode == "mujoco":
            self.simulation = start_simulation(self.config)
        self.emulators = start_emulators(self.config, self.simulation, in_process=True)
        if self.simulation is not None:
            self.simulation.start()

    def open_buses(self, ports: Sequence[str] | None, strict: bool, wait: bool = False) -> None:
        """Open each controller's bus (searching ``"auto"`` ports) and check its motors answer.

        With ``wait`` (a robot served at boot), a port that cannot be opened or motors that do
        not answer are waited for: the bus starts closed (``DxlBus.absent``) or its motors
        offline, and the sync loop opens it and pings them with backoff, as when a bus is lost.
        An ``"auto"`` port whose search finds no motor waits on the first port searched.

        Raises:
            SetupError: with ``strict`` and without ``wait``, one line listing every missing or
                mismatched motor; with ``wait``, an ``"auto"`` port and no serial port at all.
        """
        problems: list[str] = []
        used: set[str] = set()
        cfg = self.config
        for name, entry in cfg.controllers.items():
            names = cfg.motors_of_controller(name)
            if not names:
                continue
            port = self.emulators[name].url if self.mode is not None else entry.port
            if port == "auto":
                try:
                    port = self._search_port(name, used, ports)
                except (SetupError, PortError) as exc:
                    problem = (
                        f"controller {name!r} ({entry.baudrate} bps, protocol "
                        f"{entry.protocol}): {exc}"
                    )
                    waiting = self._port_to_wait_on(used, ports) if wait else None
                    if waiting is None:
                        if wait:  # no port to wait on: nothing can come
                            raise SetupError(problem) from None
                        problems.append(problem)
                        continue
                    port = waiting
            used.add(port)
            bus = self._open_bus(port, entry.baudrate, entry.protocol, entry.sync_read, wait)
            self.buses[name] = bus
            self.motors[name] = [
                Motor.from_config(n, cfg.motors[n], model_by_name(cfg.motors[n].type))
                for n in names
            ]
            if bus.is_open:
                missing = startup.check_presence(bus, name, self.motors[name])
                if wait and missing and not any(m.online for m in self.motors[name]):
                    logger.warning("%s", no_motors_message(port))
                problems += missing
        if problems:
            message = "; ".join(problems)
            if strict and not wait:
                raise SetupError(message)
            logger.warning("%s", message)

    @staticmethod
    def _open_bus(port: str, baudrate: int, protocol: int, sync_read: bool, wait: bool) -> DxlBus:
        options: dict[str, Any] = {"sync_read": None if sync_read else False}
        try:
            return DxlBus(port, baudrate, protocol, **options)
        except PortError as exc:
            if not wait:
                raise
            logger.warning("%s (%s); opening it when it appears", no_motors_message(port), exc)
            return DxlBus.absent(port, baudrate, protocol, exc, **options)

    @staticmethod
    def _port_to_wait_on(used: set[str], search: Sequence[str] | None) -> str | None:
        candidates = list(search) if search is not None else [p.device for p in list_ports()]
        free = [p for p in candidates if p not in used]
        return free[0] if free else None

    def _search_port(self, controller: str, used: set[str], search: Sequence[str] | None) -> str:
        cfg = self.config
        entry = cfg.controllers[controller]
        ids = [cfg.motors[n].id for n in cfg.motors_of_controller(controller)]
        candidates = list(search) if search is not None else [p.device for p in list_ports()]
        candidates = [p for p in candidates if p not in used]
        if not candidates:
            raise PortError("no free serial port to search: plug the adapter or give the port")
        port, _, _ = find_port(ids, candidates, [entry.baudrate], [entry.protocol])
        return port

    def prepare_motors(
        self, fix_return_delay: ReturnDelayConsent, write_angle_limits: bool
    ) -> None:
        """Per bus: first state, return delays, angle limits, torque/gains; its sync loops."""
        for name, bus in self.buses.items():
            motors = self.motors[name]
            loops = loops_for(self.config.controllers[name].syncloop)
            if not bus.is_open:  # waited for: the sync loop opens it and reads its motors
                self.syncs.append(BusSync(name, bus, motors, loops))
                continue
            startup.load_state(bus, motors)
            targets = _return_delays(self.config, (m.name for m in motors))
            issues = startup.return_delay_issues(motors, targets, bus.port)
            startup.fix_return_delays(bus, motors, issues, fix_return_delay)
            if write_angle_limits:
                startup.write_angle_limits(bus, motors)
            self._apply_settings(motors)
            self.syncs.append(BusSync(name, bus, motors, loops))

    def _apply_settings(self, motors: Iterable[Motor]) -> None:
        for motor in motors:
            entry = self.config.motors[motor.name]
            try:
                if entry.max_torque is not None and motor.model.has_torque_limit:
                    motor.torque_limit = entry.max_torque
                if entry.pid is not None:
                    motor.pid = entry.pid
            except RegisterError as exc:
                logger.warning("%s: config value not applied: %s", motor.name, exc)

    def build_sensors(self) -> None:
        """The config's sensors: real devices, the MuJoCo scene, or blank frames (ideal sim)."""
        specs = sensor_specs(self.config.sensors)
        self.sensors = build_sensors(specs, self._camera_maker(), self._imu_maker())

    def _camera_maker(self) -> CameraMaker:
        if self.mode == "mujoco":
            from poppy_core.sim.camera import sim_camera_maker

            return sim_camera_maker(self.simulation)
        if self.mode is not None:
            return dummy_camera
        return opencv_camera

    def _imu_maker(self) -> ImuMaker:
        if self.mode == "mujoco":
            from poppy_core.sim.imu import sim_imu_maker

            return sim_imu_maker(self.simulation)
        if self.mode is not None:
            return still_imu
        return device_imu

    def robot(self) -> Robot:
        """The robot of everything built so far; it owns them from now on (sync not started)."""
        cfg = self.config
        every = [m for name in cfg.controllers for m in self.motors.get(name, [])]
        for motor in every:  # pypot's dummy robot: a goal reached reads as the goal itself
            motor.ideal_plant = self.mode == "ideal"
        present = {m.name for m in every}
        groups = {g: [n for n in cfg.resolve_group(g) if n in present] for g in cfg.motorgroups}
        robot = Robot(
            every,
            groups=groups,
            syncs=self.syncs,
            buses=self.buses,
            config=cfg,
            emulators=self.emulators,
            simulation=self.simulation,
            sensors=self.sensors,
        )
        self._handed_over = True
        return robot


def no_motors_message(port: str) -> str:
    """What a robot waiting for its motors says (its log, the page)."""
    return f"no motors on {port} — is the power on?"


def _return_delays(config: RobotConfig, names: Iterable[str]) -> dict[str, float]:
    return {n: float(config.motors[n].return_delay_time or 0) for n in names}
