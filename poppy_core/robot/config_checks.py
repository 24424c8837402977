"""Whole-config checks: groups, attachments, IDs per bus, protocol of each motor model."""

from __future__ import annotations

import difflib
import logging
from collections.abc import Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from pydantic import BaseModel

from poppy_core.errors import ConfigError, UnknownModelError
from poppy_core.models import model_by_name
from poppy_core.protocol import MAX_ID, protocol_for
from poppy_core.robot.config_format import config_error

if TYPE_CHECKING:
    from poppy_core.robot.config import RobotConfig

logger = logging.getLogger(__name__)


def expand(
    names: Iterable[str], motors: Mapping[str, Any], groups: Mapping[str, Sequence[str]]
) -> list[str]:
    """Flatten motor and group names into motor names, in order, first occurrence kept.

    Args:
        names: Motor or group names (a name that is both resolves as a motor).
        motors: The motors by name.
        groups: The groups by name (a group met again, in a cycle or not, adds nothing).

    Returns:
        Motor names; names that are neither a motor nor a group are skipped.
    """
    seen: dict[str, None] = {}
    expanded: set[str] = set()
    stack = list(reversed(list(names)))
    while stack:  # depth first, in order, without recursion (a chain of groups can be long)
        name = stack.pop()
        if name in motors:
            seen.setdefault(name, None)
        elif name in groups and name not in expanded:
            expanded.add(name)
            stack.extend(reversed(groups[name]))
    return list(seen)


@dataclass
class CheckView:
    """What the whole-config checks read: motor IDs and types, controllers, groups.

    Built from a valid ``RobotConfig`` or, leniently, from a raw document whose fields did not all
    validate (values that are themselves invalid are None, so they raise no second problem).
    """

    motors: dict[str, tuple[int | None, str | None]]
    controllers: dict[str, tuple[int | None, list[str]]]
    groups: dict[str, list[str]]

    @classmethod
    def of_config(cls, config: RobotConfig) -> CheckView:
        """The view of a config valid field by field."""
        return cls(
            {name: (m.id, m.type) for name, m in config.motors.items()},
            {name: (c.protocol, list(c.attached_motors)) for name, c in config.controllers.items()},
            {name: list(items) for name, items in config.motorgroups.items()},
        )

    @classmethod
    def of_document(cls, data: Mapping[str, Any]) -> CheckView | None:
        """A lenient view of a raw document; None when its sections are not even mappings."""
        motors, controllers = data.get("motors"), data.get("controllers")
        groups = data.get("motorgroups", {})
        if not (isinstance(motors, dict) and isinstance(controllers, dict)):
            return None
        view = cls({}, {}, {})
        for name, entry in motors.items():
            if isinstance(name, str):
                entry = entry if isinstance(entry, dict) else {}
                view.motors[name] = (_valid_id(entry.get("id")), _valid_type(entry.get("type")))
        for name, entry in controllers.items():
            if isinstance(name, str) and isinstance(entry, dict):
                protocol = entry.get("protocol", 1)
                view.controllers[name] = (
                    protocol if protocol in (1, 2) and not isinstance(protocol, bool) else None,
                    _names(entry.get("attached_motors")),
                )
        if isinstance(groups, dict):
            view.groups = {k: _names(v) for k, v in groups.items() if isinstance(k, str)}
        return view


def _valid_id(value: Any) -> int | None:
    ok = isinstance(value, int) and not isinstance(value, bool) and 0 <= value <= 253
    return value if ok else None


def _valid_type(value: Any) -> str | None:
    if not isinstance(value, str):
        return None
    try:
        model_by_name(value)
    except UnknownModelError:
        return None
    return value


def _names(value: Any) -> list[str]:
    return [item for item in value if isinstance(item, str)] if isinstance(value, list) else []


def _unknown_name_reason(name: str, view: CheckView) -> str:
    candidates = [*view.motors, *view.groups]
    close = difflib.get_close_matches(name, candidates, n=1, cutoff=0.6)
    hint = f" (did you mean {close[0]!r}?)" if close else ""
    return f"no motor or group of that name{hint}"


def _check_groups(view: CheckView, source: str, problems: list[ConfigError]) -> None:
    for group, items in view.groups.items():
        if group in view.motors:
            problems.append(
                config_error(
                    source,
                    f"motorgroups.{group}",
                    items,
                    f"group name {group!r} is already a motor name",
                )
            )
        for index, item in enumerate(items):
            if item not in view.motors and item not in view.groups:
                problems.append(
                    config_error(
                        source,
                        f"motorgroups.{group}[{index}]",
                        item,
                        _unknown_name_reason(item, view),
                    )
                )
    _check_cycles(view, source, problems)


def _check_cycles(view: CheckView, source: str, problems: list[ConfigError]) -> None:
    """Report each cycle of groups once (an iterative depth-first search: chains may be long)."""
    on_path, done = 1, 2
    state: dict[str, int] = {}
    reported: set[frozenset[str]] = set()
    for root in view.groups:
        if root in state:
            continue
        state[root] = on_path
        path: list[tuple[str, Iterator[str]]] = [(root, iter(view.groups[root]))]
        while path:
            group, items = path[-1]
            for item in items:
                if item not in view.groups:
                    continue
                if state.get(item) == on_path:
                    names = [name for name, _ in path]
                    cycle = [*names[names.index(item) :], item]
                    if frozenset(cycle) not in reported:
                        reported.add(frozenset(cycle))
                        problems.append(
                            config_error(
                                source,
                                f"motorgroups.{cycle[0]}",
                                view.groups[cycle[0]],
                                "cyclic groups: " + " → ".join(cycle),
                            )
                        )
                elif item not in state:
                    state[item] = on_path
                    path.append((item, iter(view.groups[item])))
                    break
            else:
                state[group] = done
                path.pop()


def _check_controllers(view: CheckView, source: str, problems: list[ConfigError]) -> set[str]:
    owner: dict[str, str] = {}
    for cname, (protocol, attached) in view.controllers.items():
        field = f"controllers.{cname}.attached_motors"
        ids: dict[int, str] = {}
        for index, item in enumerate(attached):
            if item not in view.motors and item not in view.groups:
                problems.append(
                    config_error(
                        source, f"{field}[{index}]", item, _unknown_name_reason(item, view)
                    )
                )
                continue
            for motor in expand([item], view.motors, view.groups):
                previous = owner.get(motor)
                if previous is not None and previous != cname:
                    problems.append(
                        config_error(
                            source,
                            f"{field}[{index}]",
                            item,
                            f"motor {motor!r} is already attached to controller {previous!r}",
                        )
                    )
                if previous is not None:
                    continue
                owner[motor] = cname
                motor_id, type_name = view.motors[motor]
                if motor_id is not None:
                    _check_id(source, motor, motor_id, cname, protocol, ids, problems)
                if type_name is not None and protocol is not None:
                    _check_protocol(source, motor, type_name, cname, protocol, problems)
    return set(owner)


def _check_id(
    source: str,
    motor: str,
    motor_id: int,
    cname: str,
    protocol: int | None,
    ids: dict[int, str],
    problems: list[ConfigError],
) -> None:
    # IDs past MAX_ID are the motor's own check; a protocol may reserve some below it.
    top = MAX_ID if protocol is None else protocol_for(protocol).max_motor_id
    if top < MAX_ID and motor_id > top:
        problems.append(
            config_error(
                source,
                f"motors.{motor}.id",
                motor_id,
                f"protocol {protocol} IDs are 0-{top} (controller {cname!r})",
            )
        )
    if motor_id in ids:
        problems.append(
            config_error(
                source,
                f"motors.{motor}.id",
                motor_id,
                f"duplicate ID on controller {cname!r} (also used by {ids[motor_id]!r})",
            )
        )
    else:
        ids[motor_id] = motor


def _check_protocol(
    source: str, motor: str, type_name: str, cname: str, protocol: int, problems: list[ConfigError]
) -> None:
    model = model_by_name(type_name)
    if model.protocol != protocol:
        problems.append(
            config_error(
                source,
                f"motors.{motor}.type",
                type_name,
                f"a protocol {model.protocol} model on controller "
                f"{cname!r}, which uses protocol {protocol} (set "
                f"controllers.{cname}.protocol)",
            )
        )


def whole_config_problems(view: CheckView, source: str) -> list[ConfigError]:
    """Every problem that spans several fields, in the order found (see ``check_config``).

    Args:
        view: what the checks read.
        source: The file name (or label) for messages.

    Returns:
        The problems; empty when there is none.
    """
    problems: list[ConfigError] = []
    _check_groups(view, source, problems)
    attached = _check_controllers(view, source, problems)
    for motor in view.motors:
        if motor not in attached:
            logger.warning(
                "%s: motors.%s is attached to no controller; it will not be driven", source, motor
            )
    return problems


def _warn_typos(model: BaseModel, path: str, source: str) -> None:
    known = list(type(model).model_fields)
    for key in model.model_extra or {}:
        close = difflib.get_close_matches(key, known, n=1, cutoff=0.8)
        if close:
            logger.warning(
                "%s: %s.%s: unknown key kept as is (did you mean %s?)", source, path, key, close[0]
            )


def check_config(config: RobotConfig, source: str) -> None:
    """Run the checks that span several fields; raise every problem as one ConfigError.

    Refused: a group named like a motor, a group or an attached name that names nothing,
    cyclic groups, a motor attached to two controllers, two motors with one ID on one
    controller, a motor model whose protocol differs from its controller's. A motor attached
    to no controller is only logged as a warning (pypot ignores such motors too).

    Args:
        config: The config, already valid field by field.
        source: The file name (or label) for messages.

    Raises:
        ConfigError: The first problem found; ``problems`` lists all of them.
    """
    problems = whole_config_problems(CheckView.of_config(config), source)
    if problems:
        raise ConfigError.of_problems(problems)
    _warn_typos(config, "(top level)", source)
    for name, controller in config.controllers.items():
        _warn_typos(controller, f"controllers.{name}", source)
    for name, motor in config.motors.items():
        _warn_typos(motor, f"motors.{name}", source)
