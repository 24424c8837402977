"""Which profile a scan found: the one whose motors (IDs, models, buses) are exactly those found."""

from __future__ import annotations

import logging
from collections.abc import Sequence

from poppy_core.bus.results import FoundMotor
from poppy_core.errors import ConfigError, UnknownModelError
from poppy_core.models import model_by_name
from poppy_core.robot.config import RobotConfig
from poppy_core.robot.profiles import list_profiles, load_profile

logger = logging.getLogger(__name__)


def _model_name(name: str) -> str | None:
    try:
        return model_by_name(name).name
    except UnknownModelError:
        return None


def _ports_if_match(config: RobotConfig, found: Sequence[FoundMotor]) -> dict[str, str] | None:
    """The port of each controller of ``config`` when ``found`` is exactly its motors.

    Every motor of the profile must have been found, with its model, and nothing else; the
    motors of one controller on one port, at the controller's rate and protocol.
    """
    by_id: dict[int, list[FoundMotor]] = {}
    for motor in found:
        by_id.setdefault(motor.id, []).append(motor)
    if any(len(motors) > 1 for motors in by_id.values()) or len(by_id) != len(config.motors):
        return None
    ports: dict[str, str] = {}
    for controller_name, controller in config.controllers.items():
        seen: set[str] = set()
        for motor_name in config.motors_of_controller(controller_name):
            wanted = config.motors[motor_name]
            candidates = by_id.get(wanted.id)
            if candidates is None:
                return None
            (motor,) = candidates
            if (
                motor.model is None
                or _model_name(motor.model) != _model_name(wanted.type)
                or (motor.baudrate, motor.protocol) != (controller.baudrate, controller.protocol)
            ):
                return None
            seen.add(motor.port)
        if len(seen) != 1:
            return None
        ports[controller_name] = seen.pop()
    return ports


def matching_profile(
    found: Sequence[FoundMotor],
) -> tuple[str, RobotConfig, dict[str, str]] | None:
    """The first profile (user profiles hide installed ones of their name) that ``found`` is.

    Returns:
        The profile's name, its config, and the port where each of its controllers' motors
        were found; None when no profile has exactly these motors.
    """
    for info in list_profiles():
        try:
            config = load_profile(info.name)
        except ConfigError as exc:
            logger.debug("profile %s not compared: %s", info.name, exc)
            continue
        ports = _ports_if_match(config, found)
        if ports is None:
            continue
        return info.name, config, ports
    return None


def profile_on_port(port: str) -> str | None:
    """The profile whose motors answer on ``port`` (scanned at the rates, protocols and IDs of
    the known one-bus profiles only), None when they are no profile's."""
    from poppy_core.bus.scan import scan

    settings: set[tuple[int, int]] = set()
    ids: set[int] = set()
    for info in list_profiles():
        try:
            config = load_profile(info.name)
        except ConfigError:
            continue
        if len(config.controllers) != 1:
            continue
        settings |= {(c.baudrate, c.protocol) for c in config.controllers.values()}
        ids |= {m.id for m in config.motors.values()}
    found: list[FoundMotor] = []
    for baudrate, protocol in sorted(settings):
        found += scan(port, [baudrate], [protocol], sorted(ids), patient=False)
    match = matching_profile([f for f in found if f.model is not None])
    return match[0] if match is not None else None
