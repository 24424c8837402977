"""Virtual motors for a config: a ``VirtualBus`` per controller, its server, the MuJoCo world."""

from __future__ import annotations

from typing import Any

from poppy_core.emulator import (
    Adapter,
    Endpoint,
    Plant,
    VirtualBus,
    VirtualMotor,
    serve_link,
    serve_pty,
)
from poppy_core.errors import ConfigError
from poppy_core.models import model_by_name
from poppy_core.protocol import protocol_for
from poppy_core.robot.config import RobotConfig
from poppy_core.robot.profiles import list_profiles, load_profile, profile_dirs

__all__ = ["start_emulators", "start_simulation", "virtual_buses"]


def start_simulation(config: RobotConfig) -> Any:
    """The MuJoCo world of the config's robot (its profile's ``model.xml``), not yet running.

    Raises:
        ConfigError: the config names no profile kind with a simulation model.
    """
    from poppy_core.sim.world import Simulation  # mujoco loads only here

    kind = _model_kind(config)
    for directory in profile_dirs():
        path = directory / kind / "model.xml"
        if kind and path.is_file():
            return Simulation.from_file(path)
    raise ConfigError(
        f"no simulation model for robot kind {kind!r} (profiles/<kind>/model.xml)",
        field="profile.kind",
        value=kind,
    )


def _model_kind(config: RobotConfig) -> str:
    """The profile whose model the config's robot is: its header's kind, or for a config
    without one (pypot's JSON, ``to_pypot_dict()``) the profile with exactly its motor names."""
    if config.profile is not None:
        return config.profile.kind or config.profile.name
    names = set(config.motors)
    for info in list_profiles():
        has_model = (info.directory / "model.xml").is_file()
        if has_model and set(load_profile(info.name).motors) == names:
            return info.kind or info.name
    return ""


def _mujoco_plant(config: RobotConfig, controller: str, simulation: Any) -> Plant:
    from poppy_core.sim.plant import MotorJoint, MujocoPlant

    names = config.motors_of_controller(controller)
    links = {config.motors[name].id: MotorJoint(name) for name in names}
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
        usb2ax = protocol_for(controller.protocol).usb2ax_sync_read and controller.sync_read
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
