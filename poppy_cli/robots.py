"""The robot a command works on: built from the shared options, or the one `poppy serve` serves.

Every command that needs a robot gets it here (``build_robot``, or ``robot_config`` and
``start_robot`` when it looks at the config first; ``open_remote`` for ``--remote``), and every
one goes through ``poppy_core.assembly.from_config``: one way to build a robot.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import typer

from poppy_cli.output import EXIT_USAGE, error_line, warn_line

if TYPE_CHECKING:
    from pathlib import Path

    from poppy_core.remote import RemoteRobot
    from poppy_core.robot import Robot, RobotConfig
    from poppy_core.robot.startup import ReturnDelayIssue


def robot_config(profile: str | None, config_file: Path | None, port: str | None) -> RobotConfig:
    """The config to build: a file, or a profile (option, env var or user settings).

    A port (option, POPPY_PORT or user settings) replaces the port of a one-bus robot.
    """
    from poppy_cli.settings import resolve
    from poppy_core.robot import load_config, load_profile, with_ports

    chosen = resolve(profile, port)
    if config_file is not None:
        config = load_config(config_file)
    elif chosen.profile is not None:
        config = load_profile(chosen.profile)
    else:
        error_line(
            "no robot given: pass --profile NAME or --config FILE, set POPPY_PROFILE, "
            "or put `profile: NAME` in the user settings (see `poppy config list`)"
        )
        raise typer.Exit(EXIT_USAGE)
    if chosen.port is None:
        return config
    return with_ports(config, chosen.port, source="command line")


def build_robot(
    profile: str | None,
    config_file: Path | None,
    port: str | None,
    sim: bool | str | None,
    *,
    sensors: bool = False,
    wait_for_motors: bool = False,
) -> Robot:
    """Build and start the robot the shared options describe (see :func:`start_robot`)."""
    config = robot_config(profile, config_file, port)
    return start_robot(config, sim, sensors=sensors, wait_for_motors=wait_for_motors)


def start_robot(
    config: RobotConfig,
    sim: bool | str | None,
    *,
    sensors: bool = False,
    wait_for_motors: bool = False,
) -> Robot:
    """Build and start the robot of ``config``: the one way every command builds a robot.

    A Poppy creature (Ergo Jr, Torso, Humanoid: named by its profile, or recognised by its motor
    names) gets its behaviours attached (``poppy_core.assembly.from_config`` does it).

    Motors answering after a return delay above 0 µs slow every transaction: on a terminal the
    user is asked whether to set it to 0; otherwise it is only reported (a warning).
    The config's sensors (cameras) are built only when ``sensors`` (commands that show them).
    With ``wait_for_motors`` (a server started at boot), a missing port or silent motors are
    waited for instead of refused.
    """
    from poppy_core import from_config

    return from_config(
        config,
        sim=sim or False,
        fix_return_delay=ask_return_delay,
        sensors=sensors,
        wait_for_motors=wait_for_motors,
    )


def open_remote(url: str) -> RemoteRobot:
    """Connect to a robot served by `poppy serve --http` (token from POPPY_TOKEN)."""
    import os

    from poppy_core.remote import RemoteRobot

    return RemoteRobot(url, token=os.environ.get("POPPY_TOKEN") or None)


def ask_return_delay(issues: list[ReturnDelayIssue]) -> bool:
    """Ask (only when stdin is a terminal) whether slow return delays may be set to 0 µs; when
    not asked, or declined, say which command sets them."""
    from poppy_cli.prompts import confirm

    listed = ", ".join(str(issue) for issue in issues)
    agreed = confirm(
        f"These motors wait before answering, which slows the bus: {listed}. "
        "Set their return delay to 0 µs (EEPROM)?",
        default=True,
    )
    if not agreed:
        warn_line(return_delay_advice(issues))
    return bool(agreed)


def return_delay_advice(issues: list[ReturnDelayIssue]) -> str:
    """The warning naming the command that sets the return delays of ``issues`` to 0 µs."""
    import shlex

    from poppy_cli.options import format_ids

    by_port: dict[str, list[int]] = {}
    for issue in issues:
        by_port.setdefault(issue.port, []).append(issue.id)
    commands = " and ".join(
        f"`poppy motor set-return-delay {format_ids(ids)} 0"
        + (f" --port {shlex.quote(port)}`" if port else "`")
        for port, ids in by_port.items()
    )
    listed = ", ".join(str(issue) for issue in issues)
    return f"return delay above 0 slows every transaction: {listed}; {commands} sets it to 0"
