"""Build a plain ``Robot``: from a config, a profile, or the motors a scan finds; real or simulated.

Plain: its motors, buses, sync loops and sensors, no creature. The assembly
(``poppy_core.assembly``, the floor above every room) adds the primitive manager and the
creature: ``poppy_core.from_config``, ``from_profile`` and ``autodetect`` start from
:func:`build_plain_robot`.

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

from poppy_core.bus import DxlBus, list_ports, scan
from poppy_core.errors import ConfigError, SetupError
from poppy_core.models import model_by_name
from poppy_core.robot.build_steps import SIM_MODES, BuildSteps, SimMode, sim_mode
from poppy_core.robot.config import RobotConfig
from poppy_core.robot.config_io import ConfigSource, as_config
from poppy_core.robot.profile_match import matching_profile
from poppy_core.robot.profiles import load_profile
from poppy_core.robot.robot import Robot
from poppy_core.robot.startup import ReturnDelayConsent
from poppy_core.robot.virtual import start_emulators, start_simulation, virtual_buses

__all__ = [
    "SIM_MODES",
    "SimMode",
    "build_plain_robot",
    "detect_config",
    "profile_config",
    "start_emulators",
    "start_simulation",
    "virtual_buses",
    "with_ports",
]

logger = logging.getLogger(__name__)


def build_plain_robot(
    config: ConfigSource,
    sim: SimMode = False,
    *,
    strict: bool = True,
    fix_return_delay: ReturnDelayConsent = False,
    write_angle_limits: bool = True,
    ports: Sequence[str] | None = None,
    start_sync: bool = True,
    sensors: bool = True,
    wait_for_motors: bool = False,
) -> Robot:
    """Build and start a plain robot from a config (a ``RobotConfig``, a dict or a JSON/YAML file).

    The one way robots are built (``poppy_core.from_config`` comes here, then adds the
    creature); the steps are ``poppy_core.robot.build_steps``'s.

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
        wait_for_motors: a port that cannot be opened, or motors that do not answer, are
            waited for instead of refused: the robot starts with them offline and its sync
            loops open the port and find the motors when they appear (a robot served at boot,
            before its power is on). ``strict`` then only logs.
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
    with BuildSteps(as_config(config), sim_mode(sim)) as parts:
        parts.start_virtual_motors()
        parts.open_buses(ports, strict, wait_for_motors)
        parts.prepare_motors(fix_return_delay, write_angle_limits)
        if sensors:
            parts.build_sensors()
        robot = parts.robot()
    try:
        if start_sync:
            robot.start_sync()
    except BaseException:
        robot.close()
        raise
    return robot


def with_ports(
    config: RobotConfig, port: str | Mapping[str, str], *, source: str = "profile"
) -> RobotConfig:
    """``config`` with other ports: one port for a one-bus robot, or controller name -> port.

    Raises:
        ConfigError: one port for a robot of several buses, or an unknown controller.
    """
    data = config.to_dict()
    controllers = data["controllers"]
    if isinstance(port, str):
        if len(controllers) != 1:
            raise ConfigError(
                f"one port given but this robot has {len(controllers)} controllers "
                f"({', '.join(controllers)}): give the port of each (a mapping, or in a "
                "config file)",
                field="controllers",
            )
        port = {next(iter(controllers)): port}
    for name, value in port.items():
        if name not in controllers:
            raise ConfigError(f"no controller {name!r}", field=f"controllers.{name}")
        controllers[name]["port"] = value
    return RobotConfig.from_dict(data, source=source)


def profile_config(name: str, port: str | Mapping[str, str] | None = None) -> RobotConfig:
    """The config of an installed or user profile, on ``port`` (one controller) or on the
    controllers' ports of a mapping; None keeps the profile's (``"auto"``: searched for)."""
    config = load_profile(name)
    return config if port is None else with_ports(config, port)


def detect_config(
    port: str | None = None,
    *,
    baudrates: Iterable[int] | None = None,
    protocols: Iterable[int] = (1, 2),
    ids: Iterable[int] = range(254),
    match_profile: bool = True,
) -> RobotConfig:
    """Scan for motors and give the config of a robot made of them.

    When the motors found are exactly a profile's (IDs, models, one bus per controller at its
    rate and protocol: an Ergo Jr, a Torso...) and ``match_profile``, the config is that
    profile's on the ports found. Otherwise the motors are named ``m<id>``, one controller per
    port, with the angle limits stored in the motors (the whole range when unset).

    Args:
        port: the port to scan; None scans every port.
        baudrates: rates to try (None: the standard ones).
        protocols: protocols to try.
        ids: IDs to look for.
        match_profile: look for a profile made of the motors found.

    Raises:
        SetupError: no motor found.
    """
    ports = [port] if port is not None else [p.device for p in list_ports()]
    found = scan(ports, baudrates, protocols, ids)
    found = [f for f in found if f.model is not None]
    if not found:
        raise SetupError(f"no known motor found on {', '.join(ports) or 'any port'}")
    match = matching_profile(found) if match_profile else None
    if match is not None:
        name, profile, profile_ports = match
        logger.info("the motors found are a %s: building it from its profile", name)
        return with_ports(profile, profile_ports, source=f"profile {name}")
    controllers: dict[str, Any] = {}
    motors: dict[str, Any] = {}
    for index, device in enumerate(sorted({f.port for f in found}), start=1):
        on_port = [f for f in found if f.port == device]
        setting = max(
            {(f.baudrate, f.protocol) for f in on_port},
            key=lambda s: sum((f.baudrate, f.protocol) == s for f in on_port),
        )
        chosen = [f for f in on_port if (f.baudrate, f.protocol) == setting]
        names = [f"m{f.id}" for f in chosen]
        controllers[f"controller_{index}"] = {
            "port": device,
            "baudrate": setting[0],
            "protocol": setting[1],
            "sync_read": setting[1] == 2,
            "attached_motors": names,
        }
        with DxlBus(device, setting[0], setting[1]) as bus:
            for f in chosen:
                motors[f"m{f.id}"] = _detected_motor(bus, f.id, str(f.model))
    return RobotConfig.from_dict(
        {"controllers": controllers, "motorgroups": {}, "motors": motors}, source="autodetect"
    )


def _detected_motor(bus: DxlBus, motor_id: int, model_name: str) -> dict[str, Any]:
    model = model_by_name(model_name)
    span = model.position_range_deg / 2
    low = bus.read_register(motor_id, model, "min_position_limit")
    high = bus.read_register(motor_id, model, "max_position_limit")
    wheel = low == high == -span  # AX/MX wheel mode: both limits raw 0
    if not isinstance(low, float) or not isinstance(high, float) or not low < high:
        low, high = -span, span
    return {
        "id": motor_id,
        "type": model.name,
        "orientation": "direct",
        "offset": 0.0,
        "angle_limit": [low, high],
        "wheel_mode": wheel,
    }
