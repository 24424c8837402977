"""Chains from a robot config: its ``kinematics`` section (or its creature profile's), attached.

A config names a URDF or MJCF and its chains (see ``poppy_core.kinematics.spec``); a relative
model path starts from the config file's folder, then from the folder of the config's profile.
A Poppy creature's config without the section (a pypot JSON) gets its profile's chains.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from poppy_core.kinematics import (
    Chain,
    KinematicDescription,
    KinematicsSpec,
    MotorFrame,
    build_chains,
    find_model,
    load_description,
)
from poppy_core.kinematics.spec import ChainSpec
from poppy_core.motion.cartesian import RobotChain
from poppy_core.robot.profiles import find_profile, load_profile, profile_folders

if TYPE_CHECKING:
    from poppy_core.robot import Robot, RobotConfig
    from poppy_core.robot.config_sections import KinematicsSection

logger = logging.getLogger(__name__)


def kinematics_of(
    config: RobotConfig, kind: str | None = None
) -> tuple[KinematicsSpec, KinematicDescription] | None:
    """The config's kinematics section and the model it names; None when it has none.

    Args:
        config: the robot's config.
        kind: a creature kind whose profile's section is used when the config has none.

    Raises:
        ConfigError: a malformed section or a model that cannot be found or read.
    """
    found = model_file(config, kind)
    if found is None:
        return None
    spec, path = found
    return spec, load_description(path)


def model_file(config: RobotConfig, kind: str | None = None) -> tuple[KinematicsSpec, Path] | None:
    """The config's kinematics section and the path of the model file it names (unread).

    Raises:
        ConfigError: a malformed section or a model file that cannot be found.
    """
    section = config.kinematics
    folders: list[Path] = [config.folder] if config.folder is not None else []
    if section is None and kind is not None:
        profile = find_profile(kind)
        section = load_profile(kind).kinematics
        folders = [profile.directory]
    if section is None:
        return None
    header = config.profile
    for name in (header.kind, header.name) if header is not None else ():
        if name:
            folders += profile_folders(name)  # a calibrated user profile hides the installed one
    if kind is not None:  # a config given as a dict (pypot's JSON) names the creature's model
        folders += profile_folders(kind)
    spec = kinematics_spec(section)
    return spec, find_model(spec.model, folders)


def kinematics_spec(section: KinematicsSection) -> KinematicsSpec:
    """The kinematics leaf's plain spec of a checked section."""
    chains = tuple(
        ChainSpec(name, tuple(c.motors), tuple(c.passive), tuple(c.reversed), c.tip, c.label)
        for name, c in section.chains.items()
    )
    return KinematicsSpec(section.model, chains, section.joint_frame, tuple(section.reversed))


def chains_from_config(config: RobotConfig, kind: str | None = None) -> dict[str, Chain]:
    """The config's chains, with the config's motor orientations, offsets and limits.

    Raises:
        ConfigError: see ``kinematics_of``; a chain naming an unknown motor.
    """
    found = kinematics_of(config, kind)
    if found is None:
        return {}
    spec, description = found
    motors = {
        name: MotorFrame(
            1.0 if m.orientation == "direct" else -1.0, float(m.offset), m.user_angle_limit
        )
        for name, m in config.motors.items()
    }
    return build_chains(spec, description, motors, group_expander(config))


def group_expander(config: RobotConfig) -> Callable[[str], list[str]]:
    """Group name -> its motors (nested groups flattened); other names come back alone."""

    def expand(name: str) -> list[str]:
        return config.resolve_group(name) if name in config.motorgroups else [name]

    return expand


def attach_chains(
    robot: Robot, kind: str | None = None, control: str = "minjerk"
) -> dict[str, RobotChain]:
    """Attach the chains of the robot's config as ``robot.<chain name>``.

    Args:
        robot: a robot built from a config.
        kind: the creature kind, whose profile's chains serve when the config has none.
        control: the goto control of the chains' ``goto`` (the creature's default).

    Returns:
        Chain name -> the attached chain (empty without a kinematics section).

    Raises:
        ConfigError: a bad kinematics section, or a chain name taken by a motor or group.
    """
    if robot.config is None:
        return {}
    found = kinematics_of(robot.config, kind)
    if found is None:
        return {}
    spec, description = found
    chains: dict[str, RobotChain] = {}
    for entry in spec.chains:
        existing = robot.extensions.get(entry.name)
        if isinstance(existing, RobotChain):
            chains[entry.name] = existing
            continue
        chain = RobotChain(robot, entry.name, spec, description, control)
        robot.attach(entry.name, chain)
        chains[entry.name] = chain
    if chains:
        logger.info("chains attached: %s", ", ".join(chains))
    return chains


def robot_chains(robot: Any) -> dict[str, RobotChain]:
    """The chains attached to a robot, name -> chain (in attach order)."""
    extensions = getattr(robot, "extensions", {})
    return {name: obj for name, obj in extensions.items() if isinstance(obj, RobotChain)}
