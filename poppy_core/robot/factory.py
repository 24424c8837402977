"""Build a ``Robot``: from a config, a profile, or whatever motors a scan finds; real or simulated.

``sim=True`` starts one in-process emulator per controller (a ``VirtualBus`` with the configured
models, IDs and baud rate, reached through the in-process link ``emu://NAME``), so the robot
talks the same bytes as with hardware without a pty or serving threads in between.
``sim="mujoco"`` does the same with MuJoCo physics behind the virtual servos (one world for the
whole robot, ``robot.simulation``); ``sim=True`` / ``"ideal"`` keep the ideal servo plant.
"""

from __future__ import annotations

import logging
from collections.abc import Iterable, Mapping, Sequence
from typing import Any

from poppy_core.bus import DxlBus, find_port, list_ports, scan
from poppy_core.emulator import (
    Adapter,
    Endpoint,
    Plant,
    VirtualBus,
    VirtualMotor,
    serve_link,
    serve_pty,
)
from poppy_core.errors import ConfigError, PortError, RegisterError, SetupError
from poppy_core.models import model_by_name
from poppy_core.robot import startup
from poppy_core.robot.config import RobotConfig
from poppy_core.robot.config_io import ConfigSource, as_config
from poppy_core.robot.motor import Motor
from poppy_core.robot.profiles import load_profile, profile_dirs
from poppy_core.robot.robot import Robot
from poppy_core.robot.startup import ReturnDelayConsent
from poppy_core.robot.sync import BusSync, loops_for
from poppy_core.sensors.config import CameraMaker, build_sensors, dummy_camera, opencv_camera

logger = logging.getLogger(__name__)


SimMode = bool | str
SIM_MODES = ("ideal", "mujoco")


def _sim_mode(sim: SimMode) -> str | None:
    """None (hardware), "ideal" or "mujoco" from the ``sim`` argument."""
    if sim is False or sim is None:
        return None
    if sim is True:
        return "ideal"
    if sim in SIM_MODES:
        return str(sim)
    raise ConfigError(f"unknown simulation {sim!r} (expected one of {', '.join(SIM_MODES)})",
                      field="sim", value=sim)  # fmt: skip


def start_simulation(config: RobotConfig) -> Any:
    """The MuJoCo world of the config's robot (its profile's ``model.xml``), not yet running.

    Raises:
        ConfigError: the config names no profile kind with a simulation model.
    """
    from poppy_core.sim.world import Simulation  # mujoco loads only here

    kind = (config.profile.kind or config.profile.name) if config.profile is not None else ""
    for directory in profile_dirs():
        path = directory / kind / "model.xml"
        if kind and path.is_file():
            return Simulation(path.read_text(encoding="utf-8"))
    raise ConfigError(f"no simulation model for robot kind {kind!r} (profiles/<kind>/model.xml)",
                      field="profile.kind", value=kind)  # fmt: skip


def _mujoco_plant(config: RobotConfig, controller: str, simulation: Any) -> Plant:
    from poppy_core.sim.plant import JointLink, MujocoPlant

    names = config.motors_of_controller(controller)
    links = {config.motors[name].id: JointLink(name) for name in names}
    return MujocoPlant(simulation, links)


def virtual_buses(
    config: RobotConfig,
    simulation: Any = None,
    *,
    baudrate: int | None = None,
    set_up: bool = True,
    adapter: Adapter | None = None,
    **bus_options: Any,
) -> dict[str, VirtualBus]:
    """One virtual bus per controller with the configured models and IDs: name -> ``VirtualBus``.

    Args:
        config: the robot.
        simulation: a MuJoCo world (``start_simulation``): each bus gets a plant view on it.
        baudrate: every motor's rate (None: each controller's configured rate).
        set_up: motors already set up for poppy (return delay 0); False keeps the factory value.
        adapter: the virtual adapter; None gives protocol 1 controllers with ``sync_read`` a
            USB2AX (their configs expect its SYNC_READ) and the others a U2D2.
        **bus_options: passed to ``VirtualBus`` (``wire_timing``, ``latency_s``...).
    """
    buses: dict[str, VirtualBus] = {}
    for name, controller in config.controllers.items():
        rate = baudrate or controller.baudrate
        motors = []
        for motor_name in config.motors_of_controller(name):
            entry = config.motors[motor_name]
            virtual = VirtualMotor(model_by_name(entry.type), entry.id, rate)
            if set_up:
                virtual.table.set("return_delay_time", 0)
            motors.append(virtual)
        usb2ax = controller.protocol == 1 and controller.sync_read
        plant = None if simulation is None else _mujoco_plant(config, name, simulation)
        buses[name] = VirtualBus(
            motors,
            controller.protocol,
            baudrate=rate,
            adapter=adapter or ("usb2ax" if usb2ax else "u2d2"),
            plant=plant,
            **bus_options,
        )
    return buses


def start_emulators(
    config: RobotConfig, simulation: Any = None, *, in_process: bool = False
) -> dict[str, Any]:
    """One emulator per controller: controller name -> its server.

    The buses are ``virtual_buses(config, simulation)``: motors already set up (return delay 0).

    Args:
        config: the robot.
        simulation: a MuJoCo world behind the motors (``start_simulation``).
        in_process: offer each bus at ``emu://NAME`` (a robot in this process); False serves
            each on a pty, for other programs.
    """
    servers: dict[str, Endpoint] = {}
    try:
        for name, bus in virtual_buses(config, simulation).items():
            servers[name] = serve_link(bus) if in_process else serve_pty(bus)
    except BaseException:
        for server in servers.values():
            server.stop()
        raise
    return servers


def _resolve_port(
    controller: str, config: RobotConfig, used: set[str], search: Sequence[str] | None
) -> str:
    entry = config.controllers[controller]
    ids = [config.motors[n].id for n in config.motors_of_controller(controller)]
    candidates = list(search) if search is not None else [p.device for p in list_ports()]
    candidates = [p for p in candidates if p not in used]
    if not candidates:
        raise PortError("no free serial port to search: plug the adapter or give the port")
    port, _, _ = find_port(ids, candidates, [entry.baudrate], [entry.protocol])
    return port


def _motor_targets(config: RobotConfig, names: Iterable[str]) -> dict[str, float]:
    return {n: float(config.motors[n].return_delay_time or 0) for n in names}


def from_config(
    config: ConfigSource,
    sim: SimMode = False,
    *,
    strict: bool = True,
    fix_return_delay: ReturnDelayConsent = False,
    write_angle_limits: bool = True,
    ports: Sequence[str] | None = None,
    start_sync: bool = True,
    sensors: bool = True,
) -> Robot:
    """Build and start a robot from a config (a ``RobotConfig``, a dict or a JSON/YAML file).

    Args:
        config: the config, a dict as pypot's ``from_config(my_config)`` takes, or a file path.
        sim: serve the config's motors from in-process emulators instead of hardware: True or
            ``"ideal"`` (ideal servos), ``"mujoco"`` (physics; ``robot.simulation`` is set).
        strict: missing or mismatched motors raise ``SetupError``; when False they are logged
            and missing ones start offline (retried by the sync loop).
        fix_return_delay: set return delays above the wanted one (0 µs unless the config's
            ``return_delay_time`` says) to it: True, False (warn only) or a function shown
            the issues that returns True to fix them.
        write_angle_limits: write the configured limits to the servos' EEPROM (see
            ``poppy_core.robot.startup``).
        ports: ports searched for controllers whose port is ``"auto"`` (None: every port).
        start_sync: start the sync loops.
        sensors: build the config's sensors (cameras open their device now; each starts on
            first use): OpenCV devices on hardware, the MuJoCo scene seen from the robot with
            ``sim="mujoco"``, blank frames with the ideal simulation. False: none.

    Returns:
        The running robot (close it, or use it in a ``with`` block).

    Raises:
        ConfigError: invalid config.
        SensorError: a camera cannot be opened (missing, busy): pass ``sensors=False`` to
            drive the motors without it.
        SetupError: one line listing missing motors (with where they were searched) and
            motors whose model differs from the config.
        PortError: a port cannot be opened.
    """
    cfg = as_config(config)
    emulators: dict[str, Any] = {}
    buses: dict[str, DxlBus] = {}
    mode = _sim_mode(sim)
    simulation = start_simulation(cfg) if mode == "mujoco" else None
    try:
        if mode is not None:
            emulators = start_emulators(cfg, simulation, in_process=True)
            if simulation is not None:
                simulation.start()
        motors: dict[str, list[Motor]] = {}
        problems: list[str] = []
        used: set[str] = set()
        for name, entry in cfg.controllers.items():
            names = cfg.motors_of_controller(name)
            if not names:
                continue
            port = emulators[name].url if mode is not None else entry.port
            if port == "auto":
                try:
                    port = _resolve_port(name, cfg, used, ports)
                except (SetupError, PortError) as exc:
                    problems.append(
                        f"controller {name!r} ({entry.baudrate} bps, protocol "
                        f"{entry.protocol}): {exc}"
                    )
                    continue
            used.add(port)
            bus = DxlBus(
                port, entry.baudrate, entry.protocol, sync_read=None if entry.sync_read else False
            )
            buses[name] = bus
            motors[name] = [
                Motor.from_config(n, cfg.motors[n], model_by_name(cfg.motors[n].type))
                for n in names
            ]
            problems += startup.check_presence(bus, name, motors[name])
        if problems:
            message = "; ".join(problems)
            if strict:
                raise SetupError(message)
            logger.warning("%s", message)
        syncs = []
        for name, bus in buses.items():
            _prepare(bus, cfg, motors[name], fix_return_delay, write_angle_limits)
            loops = loops_for(cfg.controllers[name].syncloop)
            syncs.append(BusSync(name, bus, motors[name], loops))
        built = build_sensors(cfg.sensors, _camera_maker(mode, simulation)) if sensors else {}
    except BaseException:
        for bus in buses.values():
            bus.close()
        for server in emulators.values():
            server.stop()
        if simulation is not None:
            simulation.close()
        raise
    every = [m for name in cfg.controllers for m in motors.get(name, [])]
    groups = {g: [n for n in cfg.resolve_group(g) if n in {m.name for m in every}]
              for g in cfg.motorgroups}
    robot = Robot(every, groups=groups, syncs=syncs, buses=buses, config=cfg, emulators=emulators,
                  simulation=simulation, sensors=built)  # fmt: skip
    if start_sync:
        robot.start_sync()
    return robot


def _camera_maker(mode: str | None, simulation: Any) -> CameraMaker:
    """Real devices on hardware; the scene seen from the robot in MuJoCo; blank frames else."""
    if mode == "mujoco":
        from poppy_core.sim.camera import sim_camera_maker

        return sim_camera_maker(simulation)
    if mode is not None:
        return dummy_camera
    return opencv_camera


def _prepare(
    bus: DxlBus,
    cfg: RobotConfig,
    motors: list[Motor],
    fix_return_delay: ReturnDelayConsent,
    write_angle_limits: bool,
) -> None:
    """First state, return delays, angle limits and configured torque/gains of one bus."""
    startup.load_state(bus, motors)
    issues = startup.return_delay_issues(motors, _motor_targets(cfg, (m.name for m in motors)))
    startup.fix_return_delays(bus, motors, issues, fix_return_delay)
    if write_angle_limits:
        startup.write_angle_limits(bus, motors)
    for motor in motors:
        entry = cfg.motors[motor.name]
        try:
            if entry.max_torque is not None and motor.model.has_torque_limit:
                motor.torque_limit = entry.max_torque
            if entry.pid is not None:
                motor.pid = entry.pid
        except RegisterError as exc:
            logger.warning("%s: config value not applied: %s", motor.name, exc)


def _with_ports(config: RobotConfig, port: str | Mapping[str, str]) -> RobotConfig:
    data = config.to_dict()
    controllers = data["controllers"]
    if isinstance(port, str):
        if len(controllers) != 1:
            raise ConfigError(
                f"this robot has {len(controllers)} controllers ({', '.join(controllers)}): "
                "give the port of each as a mapping",
                field="controllers",
            )
        port = {next(iter(controllers)): port}
    for name, value in port.items():
        if name not in controllers:
            raise ConfigError(f"no controller {name!r}", field=f"controllers.{name}")
        controllers[name]["port"] = value
    return RobotConfig.from_dict(data, source="profile")


def from_profile(
    name: str, port: str | Mapping[str, str] | None = None, sim: SimMode = False, **options: Any
) -> Robot:
    """Build a robot from an installed or user profile (``"ergo-jr"``, ``"torso"``...).

    Args:
        name: the profile name.
        port: the port (one controller) or controller name -> port; None keeps the profile's
            (``"auto"`` searches for the bus holding the motors).
        sim: serve the motors from emulators (True/``"ideal"`` or ``"mujoco"``).
        **options: passed to :func:`from_config`.
    """
    config = load_profile(name)
    if port is not None:
        config = _with_ports(config, port)
    return from_config(config, sim, **options)


def autodetect(
    port: str | None = None,
    *,
    baudrates: Iterable[int] | None = None,
    protocols: Iterable[int] = (1, 2),
    ids: Iterable[int] = range(254),
    **options: Any,
) -> Robot:
    """Scan for motors and build a robot of them (named ``m<id>``, one controller per port).

    The angle limits are the ones stored in the motors (the whole range when unset).

    Args:
        port: the port to scan; None scans every port.
        baudrates: rates to try (None: the standard ones).
        protocols: protocols to try.
        ids: IDs to look for.
        **options: passed to :func:`from_config`.

    Raises:
        SetupError: no motor found.
    """
    ports = [port] if port is not None else [p.device for p in list_ports()]
    found = scan(ports, baudrates, protocols, ids)
    found = [f for f in found if f.model is not None]
    if not found:
        raise SetupError(f"no known motor found on {', '.join(ports) or 'any port'}")
    controllers: dict[str, Any] = {}
    motors: dict[str, Any] = {}
    for index, device in enumerate(sorted({f.port for f in found}), start=1):
        on_port = [f for f in found if f.port == device]
        setting = max({(f.baudrate, f.protocol) for f in on_port},
                      key=lambda s: sum((f.baudrate, f.protocol) == s for f in on_port))
        chosen = [f for f in on_port if (f.baudrate, f.protocol) == setting]
        names = [f"m{f.id}" for f in chosen]
        controllers[f"controller_{index}"] = {
            "port": device, "baudrate": setting[0], "protocol": setting[1],
            "sync_read": setting[1] == 2, "attached_motors": names,
        }  # fmt: skip
        with DxlBus(device, setting[0], setting[1]) as bus:
            for f in chosen:
                motors[f"m{f.id}"] = _detected_motor(bus, f.id, str(f.model))
    config = RobotConfig.from_dict(
        {"controllers": controllers, "motorgroups": {}, "motors": motors}, source="autodetect"
    )
    return from_config(config, **options)


def _detected_motor(bus: DxlBus, motor_id: int, model_name: str) -> dict[str, Any]:
    model = model_by_name(model_name)
    span = model.position_range_deg / 2
    low = bus.read_register(motor_id, model, "min_position_limit")
    high = bus.read_register(motor_id, model, "max_position_limit")
    wheel = low == high == -span  # AX/MX wheel mode: both limits raw 0
    if not isinstance(low, float) or not isinstance(high, float) or not low < high:
        low, high = -span, span
    return {"id": motor_id, "type": model.name, "orientation": "direct", "offset": 0.0,
            "angle_limit": [low, high], "wheel_mode": wheel}  # fmt: skip
