"""pypot's creature classes: ``PoppyErgoJr(...)``, ``PoppyTorso(...)``, ``PoppyHumanoid(...)``.

As in pypot, calling the class builds and returns the robot (a ``Robot`` made by the one factory,
``poppy_core.assembly.from_profile`` / ``from_config``) with the creature's behaviours attached,
and the servers asked for started by the one ``serve`` (``assembly.servers``), each attached
under pypot's name (``robot.http``, ``robot.ws``, ``robot.zmq``, ``robot.snap``). They live in the
assembly because they start servers; user code imports them from ``poppy_core.pypot``.
The constructor takes pypot's arguments; each is honoured or refused with a one-line error
saying what to use instead.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Mapping
from os import PathLike
from typing import Any, ClassVar

from poppy_core.assembly.build import from_config, from_profile
from poppy_core.assembly.serve_spec import DEFAULT_PORTS, Listen, ServeSpec
from poppy_core.assembly.servers import serve
from poppy_core.creatures.registry import CREATURES, attach_creature
from poppy_core.errors import ArgumentError, ConfigError
from poppy_core.robot import Robot

logger = logging.getLogger(__name__)

SIMULATORS: dict[str | None, bool | str] = {
    None: False,
    "dummy": True,
    "mujoco": "mujoco",
    "threejs": True,
    "poppy-simu": True,
}
"""pypot's ``simulator=`` values -> the factory's ``sim``: virtual servos with the ideal plant
(``'dummy'``; ``'threejs'`` and ``'poppy-simu'`` also serve the page with its 3D view), with
MuJoCo physics (``'mujoco'``), or hardware (None)."""
PAGE_SIMULATORS = ("threejs", "poppy-simu")
"""The simulators that serve the robot's page over HTTP (pypot's threejs and poppy-simu)."""
LOOPBACK = "127.0.0.1"


def _simulator(value: object) -> bool | str:
    if value == "vrep":
        raise ConfigError(
            "simulator='vrep' is not supported: V-REP is replaced by MuJoCo, use "
            "simulator='mujoco' (or 'dummy' for virtual servos without physics)",
            field="simulator",
            value=value,
        )
    if value not in SIMULATORS:
        raise ConfigError(
            f"unknown simulator {value!r}: use None (hardware), 'dummy', 'mujoco' or 'threejs'",
            field="simulator",
            value=value,
        )
    return SIMULATORS[value]


class AbstractPoppyCreature:
    """The creature class of pypot: ``PoppyErgoJr()`` returns the running robot.

    Args (pypot's names):
        base_path: refused (the creature's files are poppy's profiles).
        config: a config (dict, or JSON/YAML file) instead of the creature's profile.
        simulator: None (hardware), ``'dummy'`` (virtual servos, ideal plant), ``'mujoco'``
            (virtual servos in MuJoCo physics; ``robot.simulation``), ``'threejs'`` (the
            ideal virtual robot with its page and 3D view served over HTTP, the URL printed);
            ``'vrep'`` is refused.
        scene: with ``simulator='mujoco'``, an MJCF scene file holding the robot and its props
            (``robot.load_scene``); None: the profile's ``model.xml``.
        tracked_objects, tracked_collisions: with ``simulator='mujoco'``, bodies read as
            ``robot.<name>.position``/``.orientation`` and ``robot.<name>.colliding`` (pypot's
            ``from_vrep`` arguments).
        use_http, http_host, http_port: the REST server (``robot.http``).
        use_ws, ws_host, ws_port: the state stream WebSocket (``robot.ws``).
        use_zmq, zmq_host, zmq_port: pypot's ZMQ request/reply server (``robot.zmq``).
        use_snap, snap_host, snap_port: the Snap! server (``robot.snap``).
        use_remote: refused (pypot's zerorpc server): use ``use_zmq``.
        start_background_services: serve now; False binds the servers only and the script
            serves with ``robot.http.run()``...
        sync: start the sync loops.
        port: the serial port of the creature's controller (pypot: the V-REP port, refused
            as a number).
        **extra: pypot's sensor switches (``camera='dummy'``): a real robot is then built
            without its sensors.

    Hosts default to loopback (pypot: every interface): pass ``http_host='0.0.0.0'`` to serve
    the network.
    """

    kind: ClassVar[str] = ""

    def __new__(  # type: ignore[misc]  # pypot's: calling the class returns the robot
        cls,
        base_path: str | None = None,
        config: str | PathLike[str] | Mapping[str, Any] | None = None,
        simulator: str | None = None,
        scene: str | None = None,
        host: str = "localhost",
        port: str | int | None = None,
        id: int | None = None,
        shared_vrep_io: object = None,
        use_snap: bool = False,
        snap_host: str = LOOPBACK,
        snap_port: int = DEFAULT_PORTS["snap"],
        snap_quiet: bool = True,
        use_http: bool = False,
        http_host: str = LOOPBACK,
        http_port: int = DEFAULT_PORTS["http"],
        http_quiet: bool = True,
        use_remote: bool = False,
        remote_host: str = LOOPBACK,
        remote_port: int = 4242,
        use_ws: bool = False,
        ws_host: str = LOOPBACK,
        ws_port: int = DEFAULT_PORTS["ws"],
        use_zmq: bool = False,
        zmq_host: str = LOOPBACK,
        zmq_port: int = DEFAULT_PORTS["zmq"],
        start_background_services: bool = True,
        sync: bool = True,
        **extra: Any,
    ) -> Robot:
        if not cls.kind:
            raise ConfigError(
                "AbstractPoppyCreature is abstract: use PoppyErgoJr, PoppyTorso or PoppyHumanoid",
                field="kind",
            )
        sim = _simulator(simulator)
        if simulator in PAGE_SIMULATORS:
            use_http = True  # pypot: the virtual robot served over HTTP for the browser's view
        _refuse_vrep_options(base_path, port, id, shared_vrep_io, use_remote)
        scene_calls = _scene_options(sim, scene, extra)  # MuJoCo's scene and trackers
        sensors = _sensor_switches(extra)
        spec = ServeSpec(
            http=Listen(http_host, http_port) if use_http else None,
            ws=Listen(ws_host, ws_port) if use_ws else None,
            zmq=Listen(zmq_host, zmq_port) if use_zmq else None,
            snap=Listen(snap_host, snap_port) if use_snap else None,
        )
        options: dict[str, Any] = {"start_sync": sync}
        if not sensors:
            options["sensors"] = False
        serial_port = port if isinstance(port, str) else None
        if config is None:
            robot = from_profile(cls.kind, serial_port, sim, **options)
        else:
            robot = from_config(_config_source(config), sim, **options)
        try:
            cls.setup(robot)
            scene_calls(robot)
            if sim:
                hold_start_pose(robot)
            if spec.listens():
                start_services(robot, spec, start_background_services)
            if simulator in PAGE_SIMULATORS:
                announce_page(robot, http_host)
        except BaseException:
            robot.close()
            raise
        return robot

    @classmethod
    def setup(cls, robot: Robot) -> None:
        """Make ``robot`` this creature: its behaviours (if the config did not name it) and
        pypot's goto behaviour of the creature on every motor."""
        creature = robot.extensions.get("creature")
        if getattr(creature, "kind", None) != cls.kind:
            attach_creature(robot, cls.kind)
        control = CREATURES[cls.kind].goto_control
        for motor in robot.motors:
            motor.goto_behavior = control


def start_services(robot: Robot, spec: ServeSpec, start: bool) -> None:
    """Serve ``spec`` (one server set) and attach each server as ``robot.<name>``, pypot's
    names; ``robot.close()`` stops them all, in the set's order.

    Args:
        start: serve now (pypot's ``start_background_services``); False binds only, the
            caller serves with ``robot.<name>.run()``.

    Raises:
        ListenError: a port is taken or an address unusable (nothing is left serving).
    """
    servers = serve(robot, spec, start=start)
    robot.on_close(servers.stop)
    for name, server in servers.servers.items():
        robot.attach(name, server)


def announce_page(robot: Robot, host: str) -> None:
    """Log and print where the robot's page with its 3D view is (pypot's threejs simulator
    had the browser page of poppy-simu draw the robot)."""
    server = robot.extensions.get("http")
    port = getattr(server, "port", None)
    if port is None:
        return
    shown = "127.0.0.1" if host in ("0.0.0.0", "::", "") else host
    if ":" in shown:
        shown = f"[{shown}]"
    url = f"http://{shown}:{port}/"
    logger.info("the robot's page with its 3D view: %s", url)
    print(f"The robot's page with its 3D view: {url}", flush=True)


def hold_start_pose(robot: Robot) -> None:
    """Turn the torque on and hold the pose the robot starts in, as pypot's simulated robots do.

    pypot's V-REP and dummy robots follow their goals from the start, so the documentation's
    simulation examples set ``goal_position`` without turning compliance off first. Virtual
    servos power on compliant, as real ones do: a free-standing MuJoCo Humanoid would fall
    before the script's first line. In MuJoCo the world is reset to its start pose (the robot
    standing, seated on its support...) and the motors hold it.
    """
    robot.compliant = False  # each motor's goal: its present position
    simulation = robot.simulation
    if simulation is not None:
        simulation.reset()
        for motor in robot.motors:
            motor.goal_position = motor.to_user(simulation.joint_deg(motor.name))


def _config_source(config: object) -> Any:
    if isinstance(config, str | PathLike | Mapping):
        return config
    raise ConfigError(
        f"config must be a file path or a dict, not {type(config).__name__}", field="config"
    )


def _refuse_vrep_options(
    base_path: object, port: object, id: object, shared: object, remote: bool
) -> None:
    if base_path is not None:
        raise ConfigError(
            "base_path is not supported: the creature's files are poppy profiles; "
            "give config= a config file instead",
            field="base_path",
        )
    if port is not None and not isinstance(port, str):
        raise ConfigError(
            f"port={port!r} is V-REP's port: give the serial port as a string "
            "(port='/dev/ttyUSB0') or leave it out",
            field="port",
        )
    if id is not None or shared is not None:
        raise ConfigError("id= and shared_vrep_io= are V-REP options: leave them out", field="id")
    if remote:
        raise ConfigError(
            "use_remote (pypot's zerorpc server) is not supported: use "
            "use_zmq=True (pypot's ZMQ server) or use_http=True",
            field="use_remote",
        )


def _scene_options(sim: bool | str, scene: object, extra: dict[str, Any]) -> Any:
    """What the robot gets once built from pypot's V-REP scene arguments, on MuJoCo: the scene
    file loaded, objects and collisions tracked (taken out of ``extra``)."""
    tracked = extra.pop("tracked_objects", None) or []
    collisions = extra.pop("tracked_collisions", None) or []
    if sim != "mujoco" and (scene is not None or tracked or collisions):
        raise ConfigError(
            "scene=, tracked_objects= and tracked_collisions= need simulator='mujoco' "
            "(the scene is an MJCF file holding the robot and its props)",
            field="scene" if scene is not None else "tracked_objects",
            value=scene,
        )
    path = None
    if scene is not None:
        if not isinstance(scene, (str, os.PathLike)) or os.fspath(scene) == "keep-existing":
            raise ConfigError(
                f"scene={scene!r}: give the path of an MJCF scene file (start from a copy of "
                "the profile's model.xml and add props), or leave it out",
                field="scene",
                value=scene,
            )
        path = os.fspath(scene)
        if str(path).lower().endswith(".ttt"):
            raise ConfigError(
                f"scene={scene!r} is a V-REP scene: MuJoCo reads an MJCF file (start from a "
                "copy of the profile's model.xml and add props)",
                field="scene",
                value=scene,
            )

    def apply(robot: Robot) -> None:
        if path is not None:
            robot.load_scene(path)
        if tracked:
            robot.track_objects(tracked)
        if collisions:
            robot.track_collisions(collisions)

    return apply


def _sensor_switches(extra: Mapping[str, Any]) -> bool:
    """False when pypot's ``<sensor>='dummy'`` switches ask for no real sensor."""
    for key, value in extra.items():
        if value != "dummy":
            raise ArgumentError(
                f"unexpected argument {key}={value!r}: the creature classes take pypot's "
                "arguments (config, simulator, use_http, http_port, use_ws, use_zmq, use_snap, "
                "start_background_services, sync...) and <sensor>='dummy'",
                field=key,
                value=value,
            )
    return not extra


class PoppyErgoJr(AbstractPoppyCreature):
    """Poppy Ergo Jr: ``PoppyErgoJr()`` (hardware) or ``PoppyErgoJr(simulator='dummy')``."""

    kind = "ergo-jr"


class PoppyTorso(AbstractPoppyCreature):
    """Poppy Torso: ``PoppyTorso()`` or ``PoppyTorso(simulator='mujoco')``."""

    kind = "torso"


class PoppyHumanoid(AbstractPoppyCreature):
    """Poppy Humanoid: ``PoppyHumanoid()`` or ``PoppyHumanoid(simulator='mujoco')``."""

    kind = "humanoid"
