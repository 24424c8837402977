"""Whole-config checks: groups, attachments, IDs per bus, protocol of each motor model."""

from __future__ import annotations

import difflib
import logging
from collections.abc import Iterable, Mapping, Sequence
from typing import TYPE_CHECKING, Any

from pydantic import BaseModel

from poppy_core.errors import UnknownModelError
from poppy_core.models import model_by_name
from poppy_core.robot.config_format import config_error

if TYPE_CHECKING:
    from poppy_core.robot.config import RobotConfig

logger = logging.getLogger(__name__)

# e-manual: Protocol 2.0, Packet / ID: usable IDs are 0-252 (0x00-0xFC); 0xFD is reserved
# (it is part of the header), 0xFE is broadcast. Protocol 1.0 allows 0-253.
MAX_PROTOCOL2_ID = 252


def expand(
    names: Iterable[str], motors: Mapping[str, Any], groups: Mapping[str, Sequence[str]]
) -> list[str]:
    """Flatten motor and group names into motor names, in order, first occurrence kept.

    Args:
        names: Motor or group names (a name that is both resolves as a motor).
        motors: The motors by name.
        groups: The groups by name; must be free of cycles (``check_config`` ensures it).

    Returns:
        Motor names; names that are neither a motor nor a group are skipped.
    """
    seen: dict[str, None] = {}

    def visit(name: str) -> None:
        if name in motors:
            seen.setdefault(name, None)
        elif name in groups:
            for item in groups[name]:
                visit(item)

    for name in names:
        visit(name)
    return list(seen)


def _unknown_name_reason(name: str, config: RobotConfig) -> str:
    candidates = [*config.motors, *config.motorgroups]
    close = difflib.get_close_matches(name, candidates, n=1, cutoff=0.6)
    hint = f" (did you mean {close[0]!r}?)" if close else ""
    return f"no motor or group of that name{hint}"


def _check_groups(config: RobotConfig, source: str) -> None:
    for group, items in config.motorgroups.items():
        if group in config.motors:
            raise config_error(source, f"motorgroups.{group}", items,
                               f"group name {group!r} is already a motor name")
        for index, item in enumerate(items):
            if item not in config.motors and item not in config.motorgroups:
                raise config_error(source, f"motorgroups.{group}[{index}]", item,
                                   _unknown_name_reason(item, config))
    _check_cycles(config, source)


def _check_cycles(config: RobotConfig, source: str) -> None:
    done: set[str] = set()

    def visit(group: str, stack: list[str]) -> None:
        if group in stack:
            cycle = [*stack[stack.index(group):], group]
            first = cycle[0]
            raise config_error(source, f"motorgroups.{first}", config.motorgroups[first],
                               "cyclic groups: " + " → ".join(cycle))
        if group in done:
            return
        for item in config.motorgroups[group]:
            if item in config.motorgroups:
                visit(item, [*stack, group])
        done.add(group)

    for group in config.motorgroups:
        visit(group, [])


def _check_controllers(config: RobotConfig, source: str) -> None:
    owner: dict[str, str] = {}
    for cname, controller in config.controllers.items():
        field = f"controllers.{cname}.attached_motors"
        ids: dict[int, str] = {}
        for index, item in enumerate(controller.attached_motors):
            if item not in config.motors and item not in config.motorgroups:
                raise config_error(source, f"{field}[{index}]", item,
                                   _unknown_name_reason(item, config))
            for motor in expand([item], config.motors, config.motorgroups):
                previous = owner.get(motor)
                if previous is not None and previous != cname:
                    raise config_error(source, f"{field}[{index}]", item,
                                       f"motor {motor!r} is already attached to controller "
                                       f"{previous!r}")
                if previous == cname:
                    continue
                owner[motor] = cname
                motor_id = config.motors[motor].id
                if controller.protocol == 2 and motor_id > MAX_PROTOCOL2_ID:
                    raise config_error(source, f"motors.{motor}.id", motor_id,
                                       f"protocol 2 IDs are 0-{MAX_PROTOCOL2_ID} (controller "
                                       f"{cname!r})")
                if motor_id in ids:
                    raise config_error(source, f"motors.{motor}.id", motor_id,
                                       f"duplicate ID on controller {cname!r} "
                                       f"(also used by {ids[motor_id]!r})")
                ids[motor_id] = motor
                _check_protocol(config, source, motor, cname)
    for motor in config.motors:
        if motor not in owner:
            logger.warning("%s: motors.%s is attached to no controller; it will not be driven",
                           source, motor)


def _check_protocol(config: RobotConfig, source: str, motor: str, cname: str) -> None:
    type_name = config.motors[motor].type
    try:
        model = model_by_name(type_name)
    except UnknownModelError:  # already refused by the field check; kept for safety
        return
    protocol = config.controllers[cname].protocol
    if model.protocol != protocol:
        raise config_error(source, f"motors.{motor}.type", type_name,
                           f"a protocol {model.protocol} model on controller {cname!r}, which "
                           f"uses protocol {protocol} (set controllers.{cname}.protocol)")


def _warn_typos(model: BaseModel, path: str, source: str) -> None:
    known = list(type(model).model_fields)
    for key in model.model_extra or {}:
        close = difflib.get_close_matches(key, known, n=1, cutoff=0.8)
        if close:
            logger.warning("%s: %s.%s: unknown key kept as is (did you mean %s?)",
                           source, path, key, close[0])


def check_config(config: RobotConfig, source: str) -> None:
    """Run the checks that span several fields; raise the first problem as a ConfigError.

    Refused: a group named like a motor, a group or an attached name that names nothing,
    cyclic groups, a motor attached to two controllers, two motors with one ID on one
    controller, a motor model whose protocol differs from its controller's. A motor attached
    to no controller is only logged as a warning (pypot ignores such motors too).

    Args:
        config: The config, already valid field by field.
        source: The file name (or label) for messages.

    Raises:
        ConfigError: The first problem found.
    """
    _check_groups(config, source)
    _check_controllers(config, source)
    _warn_typos(config, "(top level)", source)
    for name, controller in config.controllers.items():
        _warn_typos(controller, f"controllers.{name}", source)
    for name, motor in config.motors.items():
        _warn_typos(motor, f"motors.{name}", source)
