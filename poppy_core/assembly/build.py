"""Build a robot whole: the plain robot of ``robot.factory``, its primitive manager and creature.

User code reaches ``from_config``, ``from_profile`` and ``autodetect`` as the package's faces
(``poppy_core.from_profile``...) and pypot's ``from_json`` in ``poppy_core.pypot``.
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Mapping
from typing import Any

from poppy_core.creatures.attach import attach_behaviours
from poppy_core.errors import ArgumentError
from poppy_core.motion.manager import primitive_manager
from poppy_core.robot import factory
from poppy_core.robot.config_io import ConfigSource
from poppy_core.robot.factory import SimMode, profile_config
from poppy_core.robot.robot import Robot

__all__ = ["autodetect", "from_config", "from_json", "from_profile"]


def from_config(
    config: ConfigSource,
    sim: SimMode = False,
    *,
    creature: bool = True,
    start_defaults: bool = True,
    **options: Any,
) -> Robot:
    """Build and start a robot from a config (a ``RobotConfig``, a dict or a JSON/YAML file).

    The one way robots are built (the CLI, the server, the TUI, ``from_profile``,
    ``autodetect`` and the creature classes all come here): the plain robot of
    ``poppy_core.robot.factory.build_plain_robot``, its primitive manager
    (``robot.primitive_manager``, pypot's ``robot._primitive_manager``), and what the config
    makes it.

    Args:
        config: the config, a dict as pypot's ``from_config(my_config)`` takes, or a file path.
        sim: serve the config's motors from in-process emulators instead of hardware: True or
            ``"ideal"`` (ideal servos), ``"mujoco"`` (physics; ``robot.simulation`` is set).
        creature: attach what the config makes the robot (``creatures.attach``): a Poppy
            creature's primitives and postures (``robot.dance``...), or the kinematic chains
            its config describes. False: a bare robot.
        start_defaults: start the primitives the creature starts by default.
        **options: ``strict``, ``fix_return_delay``, ``write_angle_limits``, ``ports``,
            ``start_sync``, ``sensors``: see ``poppy_core.robot.factory.build_plain_robot``.

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
    robot = factory.build_plain_robot(config, sim, **options)
    try:
        primitive_manager(robot)
        if creature:
            attach_behaviours(robot, start_defaults=start_defaults)
    except BaseException:
        robot.close()
        raise
    return robot


def from_profile(
    name: str,
    port: str | Mapping[str, str] | None = None,
    sim: SimMode = False,
    **options: Any,
) -> Robot:
    """Build a robot from an installed or user profile (``"ergo-jr"``, ``"torso"``...).

    Args:
        name: the profile name.
        port: the port (one controller) or controller name -> port; None keeps the profile's
            (``"auto"`` searches for the bus holding the motors).
        sim: serve the motors from emulators (True/``"ideal"`` or ``"mujoco"``).
        **options: passed to :func:`from_config` (``start_defaults``, ``creature``...).
    """
    return from_config(profile_config(name, port), sim, **options)


def autodetect(
    port: str | None = None,
    *,
    baudrates: Iterable[int] | None = None,
    protocols: Iterable[int] = (1, 2),
    ids: Iterable[int] = range(254),
    **options: Any,
) -> Robot:
    """Scan for motors and build a robot of them.

    When the motors found are exactly a profile's (IDs, models, one bus per controller at its
    rate and protocol: an Ergo Jr, a Torso...), the robot is built from that profile, as
    :func:`from_profile` on the ports found would: its names, groups, orientations, limits and
    its creature (``robot.dance``...). Otherwise (or with ``creature=False``) the motors are
    named ``m<id>``, one controller per port, with the angle limits stored in the motors (the
    whole range when unset).

    Args:
        port: the port to scan; None scans every port.
        baudrates: rates to try (None: the standard ones).
        protocols: protocols to try.
        ids: IDs to look for.
        **options: passed to :func:`from_config`; ``creature=False`` builds a bare robot of
            the motors found. ``sensors`` defaults to False here (a scan finds motors, not
            cameras): pass ``sensors=True`` for a matched profile's camera.

    Raises:
        SetupError: no motor found.
    """
    options.setdefault("sensors", False)
    config = factory.detect_config(
        port,
        baudrates=baudrates,
        protocols=protocols,
        ids=ids,
        match_profile=options.get("creature", True),
    )
    return from_config(config, **options)


def from_json(
    json_file: str | os.PathLike[str],
    sync: bool = True,
    strict: bool = True,
    use_dummy_io: bool = False,
    **options: Any,
) -> Robot:
    """Build a robot from a pypot JSON config file, as ``pypot.robot.from_json`` does.

    Args:
        json_file: the config file (pypot JSON; poppy's YAML works too).
        sync: start the sync loops.
        strict: missing or mismatched motors raise ``SetupError``.
        use_dummy_io: serve the motors from virtual servos instead of hardware.
        **options: passed to :func:`from_config`.

    Returns:
        The running robot (with its creature when the config is a Poppy creature's).
    """
    if not isinstance(json_file, str | os.PathLike):
        raise ArgumentError(
            f"from_json takes a file path, not {type(json_file).__name__}: use from_config for "
            "a dict",
            field="json_file",
            value=json_file,
        )
    return from_config(
        os.fspath(json_file), sim=bool(use_dummy_io), strict=strict, start_sync=sync, **options
    )
