"""Shell completion of values: profiles, serial ports, moves, registers, primitives.

Each function is a Typer ``autocompletion=`` callback: it returns ``(value, help)`` pairs and
Typer keeps those that start with what was typed. They are lazy and quick: they read folders and
data tables, list ports without opening them, never start a robot, a server or a simulator, and
complete nothing rather than fail (a completion must never print a traceback into the shell).
"""

from __future__ import annotations

import logging
import os
from collections.abc import Callable
from typing import Any

import typer

logger = logging.getLogger(__name__)

Choices = list[tuple[str, str]]


def _quietly(find: Callable[[], Choices]) -> Choices:
    """``find()``, or nothing when it fails (logged at debug level)."""
    try:
        return find()
    except Exception:  # a broken profile or settings file must not break the shell
        logger.debug("completion failed", exc_info=True)
        return []


def _is_path(text: str) -> bool:
    return text.startswith((".", "/", "~")) or os.sep in text


def profiles(incomplete: str) -> Choices:
    """Profile names (installed and user profiles) with their description."""

    def find() -> Choices:
        from poppy_core.robot.profiles import list_profiles

        return [(info.name, info.description) for info in list_profiles()]

    return [] if _is_path(incomplete) else _quietly(find)


def ports(incomplete: str) -> Choices:
    """The serial ports of this machine (listed, not opened), recognised adapters first."""

    def find() -> Choices:
        from poppy_core.bus.ports import list_ports

        return [(info.device, info.adapter or info.description) for info in list_ports()]

    return _quietly(find)


def moves(incomplete: str) -> Choices:
    """The names of the moves in the library (a path is left to the shell's file completion)."""

    def find() -> Choices:
        from poppy_core.motion.move_library import list_moves

        names = dict.fromkeys(entry.name for entry in list_moves())
        return [(name, "move") for name in names]

    return [] if _is_path(incomplete) else _quietly(find)


def _register_names(writable_only: bool) -> Choices:
    from poppy_core.models import ALL_MODELS

    names: dict[str, str] = {}
    for model in ALL_MODELS:
        for name, register in model.registers.items():
            if not writable_only or register.writable:
                names.setdefault(name, register.access)
        for alias, target in model.aliases.items():
            found = model.registers.get(target)
            if found is not None and (not writable_only or found.writable):
                names.setdefault(alias, found.access)
    return sorted(names.items())


def registers(incomplete: str) -> Choices:
    """Register names of the known servo models (the motor is not asked: no port is opened)."""
    return _quietly(lambda: _register_names(writable_only=False))


def writable_registers(incomplete: str) -> Choices:
    """The names of registers that can be written."""
    return _quietly(lambda: _register_names(writable_only=True))


def engines(incomplete: str) -> Choices:
    """The simulation engines of ``--sim``."""
    return [("mujoco", "MuJoCo physics"), ("ideal", "ideal servos")]


def on_off(incomplete: str) -> Choices:
    """``on`` or ``off``."""
    return [("on", ""), ("off", "")]


def primitives(ctx: typer.Context, incomplete: str) -> Choices:
    """The primitives of the robot named on the command line (its creature's and the built-ins).

    The robot is not built: its creature is read from the profile (``--profile``, POPPY_PROFILE
    or the user settings) or from the config file (``--config``).
    """

    def find() -> Choices:
        from poppy_core.motion.builtins import BUILTINS

        names = [(name, "built-in") for name in BUILTINS]
        try:
            kind = _creature_kind(ctx.params)
        except Exception:  # an unknown profile, a broken config: the built-ins still
            logger.debug("no creature for completion", exc_info=True)
            kind = None
        if kind is not None:
            from poppy_core.creatures.registry import CREATURES

            names = [(name, kind) for name in CREATURES[kind].primitives] + names
        return names

    return _quietly(find)


def _creature_kind(params: dict[str, Any]) -> str | None:
    """The creature kind of the robot the options name, None when unknown."""
    from poppy_core.creatures.registry import detect_kind, normalize_kind

    config_file = params.get("config_file")
    if config_file:
        from poppy_core.robot import load_config

        return detect_kind(load_config(config_file))
    from poppy_cli.settings import resolve

    profile = resolve(params.get("profile")).profile
    if profile is None:
        return None
    from poppy_core.robot.profiles import find_profile

    info = find_profile(profile)
    return normalize_kind(info.kind or info.name)
