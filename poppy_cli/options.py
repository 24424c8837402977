"""Options shared by commands (robot, bus, output, --sim); parsers of IDs, rates, protocols."""

from __future__ import annotations

import os
import re
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import typer
from typer.core import TyperCommand, TyperGroup

from poppy_cli import complete
from poppy_core import checks
from poppy_core.errors import ArgumentError
from poppy_core.trajectory import MAX_DURATION_S

if TYPE_CHECKING:
    from typer import _click


MAX_ID = 253
"""The largest Dynamixel ID (254 is the broadcast ID)."""


def _checked_id(value: int) -> int:
    try:
        return checks.count(value, 0, MAX_ID, "ID")
    except ArgumentError:
        raise typer.BadParameter(
            f"ID {value} is out of range; Dynamixel IDs are 0-{MAX_ID}"
        ) from None


def parse_ids(text: str) -> list[int]:
    """Parse "0-253", "1,2,5-7" into a sorted list of IDs in 0..253.

    Both ends of a range are checked before it is expanded: ``0-99999999999999999999`` is one
    line at once (expanding it first took gigabytes).
    """
    ids: set[int] = set()
    for part in text.replace(" ", "").split(","):
        if not part:
            continue
        try:
            if "-" in part:
                lo_text, hi_text = part.split("-", 1)
                lo, hi = int(lo_text), int(hi_text)
                if lo > hi:
                    raise typer.BadParameter(
                        f"range {part!r} goes backwards; write it as {hi}-{lo}"
                    )
                ids.update(range(_checked_id(lo), _checked_id(hi) + 1))
            else:
                ids.add(_checked_id(int(part)))
        except ValueError:
            raise typer.BadParameter(
                f"{part!r} is not an ID or a range; use e.g. 1-6 or 1,3,11-15"
            ) from None
    if not ids:
        raise typer.BadParameter("no ID given; use e.g. 0-253 or 1,2,3")
    return sorted(ids)


def format_ids(ids: list[int]) -> str:
    """IDs as ``parse_ids`` reads them, runs shortened: [1, 2, 3, 5] -> "1-3,5"."""
    runs: list[list[int]] = []
    for motor_id in sorted(set(ids)):
        if runs and motor_id == runs[-1][-1] + 1:
            runs[-1].append(motor_id)
        else:
            runs.append([motor_id])
    return ",".join(
        str(run[0]) if len(run) == 1 else f"{run[0]}{'-' if len(run) > 2 else ','}{run[-1]}"
        for run in runs
    )


def parse_protocols(text: str) -> list[int]:
    """Parse "1", "2" or "both"."""
    value = text.strip().lower()
    if value == "both":
        return [1, 2]
    if value in ("1", "2", "1.0", "2.0"):
        return [int(float(value))]
    raise typer.BadParameter(f"protocol {text!r} is not 1, 2 or both")


def default_port(port: str | None) -> str | None:
    """The port given, or POPPY_PORT from the environment, or the user settings' ``port``."""
    from poppy_cli.settings import PORT_ENV, load_settings

    return port or os.environ.get(PORT_ENV) or load_settings().port


# Dynamixel rates run from 9,600 bps (the slowest code of AX/MX/X) to 10.5 Mbps (X-series); the
# range is left a little wider for adapters, and refuses 0 or a rate no UART takes.
MIN_BAUD = 1_200
MAX_BAUD = 12_000_000
BAUD_LIMITS = {"min": MIN_BAUD, "max": MAX_BAUD}
"""Kept for callers; write ``typer.Option(..., min=MIN_BAUD, max=MAX_BAUD)`` (typed): a rate
out of range is a usage error (exit 2)."""


def finite(value: float | None) -> float | None:
    """An option callback: NaN, infinities and numbers past ``checks.MAX_MAGNITUDE`` are usage
    errors (Click's range check lets NaN by, and an option without a maximum lets 1e309 by).

    Every float option of the CLI has it, with a ``min`` and a ``max`` unless the library
    checks the range itself against the motor's model (a return delay, angle limits);
    tests/cli/test_hostile_numbers.py holds them to it.
    """
    if value is None:
        return None
    try:
        return checks.number(value)
    except ArgumentError:
        raise typer.BadParameter(f"{value} is not a finite number of a sensible size") from None


def checked(rule: Callable[[float], float]) -> Callable[[float | None], float | None]:
    """An option callback applying ``rule`` (a ``poppy_core.checks`` rule) to the value: its
    ``ArgumentError`` becomes a usage error (exit 2) saying what is accepted."""

    def callback(value: float | None) -> float | None:
        if value is None:
            return None
        try:
            return rule(value)
        except ArgumentError as exc:
            raise typer.BadParameter(str(exc).removeprefix("value ")) from None

    return callback


PORT_HELP = (
    "Serial port: a device (/dev/ttyUSB0), a pty, or a URL (socket://127.0.0.1:4000)."
    " [env: POPPY_PORT]"
)
BAUD_HELP = "Baud rate in bps (default: search the standard rates)."
PROTOCOL_HELP = "Dynamixel protocol: 1 or 2 (default: search both)."
SIM_ENGINES = ("ideal", "mujoco")


# -- each shared option is defined here once; a command may say in its help what it does -------


def port_option(help: str = PORT_HELP) -> Any:
    """``--port/-p PORT`` (None when not given; ``default_port`` adds POPPY_PORT)."""
    return typer.Option(None, "--port", "-p", help=help, autocompletion=complete.ports)


def json_option(help: str = "Print JSON instead of a table.") -> Any:
    """``--json``: print JSON for scripts instead of the human output."""
    return typer.Option(False, "--json", help=help)


def profile_option(help: str, default: str | None = None) -> Any:
    """``--profile NAME``: a robot profile (``poppy_core.robot.profiles``)."""
    return typer.Option(default, "--profile", help=help, autocompletion=complete.profiles)


def _sim_engine(value: str | None) -> str | None:
    """Check the engine of ``--sim`` (the root group turns a bare ``--sim`` into ``ideal``)."""
    if value is not None and value not in SIM_ENGINES:
        raise typer.BadParameter(f"{value!r}: use --sim (ideal servos) or --sim mujoco (physics)")
    return value


def sim_option(help: str, flag: str = "--sim") -> Any:
    """``--sim [mujoco]``: a bare ``--sim`` is ``ideal`` (see ``SimArgsGroup``); ``flag``: another
    name of such an option (``--follower-sim``)."""
    return typer.Option(
        None,
        flag,
        metavar="[mujoco]",
        callback=_sim_engine,
        help=help,
        autocompletion=complete.engines,
    )


def duration_option(default: float | None, help: str, *, minimum: float = 0.0) -> Any:
    """``--duration/-d SECONDS``: finite, from ``minimum`` up to a day (``MAX_DURATION_S``)."""
    return typer.Option(
        default,
        "--duration",
        "-d",
        min=minimum,
        max=MAX_DURATION_S,
        callback=finite,
        help=help,
    )


StopAfterOpt = duration_option(None, "Stop after this many seconds.", minimum=0.1)
"""``--duration`` of the commands that run until Ctrl-C (record, teleop)."""
BaudOpt = typer.Option(None, "--baud", "-b", help=BAUD_HELP, min=MIN_BAUD, max=MAX_BAUD)
ProtoOpt = typer.Option(None, "--protocol", help=PROTOCOL_HELP, min=1, max=2)
BusPortOpt = port_option()
"""``--port`` of the commands that work on a bus (scan, motor, config generate)."""
JsonOpt = json_option()
JsonSummaryOpt = json_option("Print a JSON summary.")


# -- the robot options of every command that builds one ----------------------------------------

ProfileOpt = profile_option("Robot profile, e.g. ergo-jr. [env: POPPY_PROFILE, or user settings]")
ConfigOpt = typer.Option(None, "--config", "-c", help="Robot config file (JSON or YAML).")
PortOpt = port_option("Serial port of the robot's bus. [env: POPPY_PORT]")
SimOpt = sim_option("Build a virtual robot: --sim (ideal servos) or --sim mujoco (MuJoCo physics).")
RemoteOpt = typer.Option(
    None,
    "--remote",
    help="Drive a robot served by `poppy serve --http` at this URL, or by `poppy serve --zenoh` "
    "as zenoh:NAME (endpoints: env POPPY_ZENOH_CONNECT; token: env POPPY_TOKEN).",
)


# -- `--sim [ENGINE]`: an option whose value may be left out ---------------------------------


def command_path(group: TyperGroup, ctx: _click.Context, args: list[str]) -> tuple[list[str], Any]:
    """The words naming the (sub)command ``args`` runs (e.g. ``["motor", "reset"]``) and that
    command (through nested groups; ``group`` itself when ``args`` names none)."""
    path: list[str] = []
    command: Any = group
    for token in args:
        if token == "--":
            break
        if token.startswith("-"):
            continue
        if not hasattr(command, "get_command"):
            break
        found = command.get_command(ctx, token)
        if found is None:
            break
        path.append(token)
        command = found
    return path, command


def _leaf_command(group: TyperGroup, ctx: _click.Context, args: list[str]) -> Any:
    """The command ``args`` will run (through nested groups), or None."""
    command = command_path(group, ctx, args)[1]
    return None if command is group else command


SIM_FLAGS = ("--sim", "--follower-sim")
"""The options whose engine may be left out (``--sim``, ``--follower-sim``: ideal)."""


def _sim_takes_value(command: Any, flag: str = "--sim") -> bool:
    for param in getattr(command, "params", []):
        if flag in getattr(param, "opts", []):
            return not getattr(param, "is_flag", True)
    return False


def normalise_sim_args(
    args: list[str],
    engines: tuple[str, ...] = SIM_ENGINES,
    flag: str = "--sim",
    any_word: bool = False,
) -> list[str]:
    """``--sim`` alone -> ``--sim=ideal``; ``--sim ENGINE`` -> ``--sim=ENGINE`` (words kept).

    So ``--sim`` stays a bare flag in every command line (``poppy robot goto --sim m1=30``)
    while ``--sim mujoco`` picks the physics engine. ``flag`` names another such option;
    ``any_word``: the command takes no argument, so any word after ``flag`` is its engine (a
    wrong one is refused by name rather than as an extra argument).
    """
    out: list[str] = []
    index = 0
    while index < len(args):
        token = args[index]
        if token == "--":
            return out + args[index:]
        if token == flag:
            following = args[index + 1] if index + 1 < len(args) else None
            if following in engines or (
                any_word and following is not None and not following.startswith("-")
            ):
                out.append(f"{flag}={following}")
                index += 2
                continue
            token = f"{flag}=ideal"
        out.append(token)
        index += 1
    return out


class SimArgsGroup(TyperGroup):
    """The root group: lets ``--sim`` take an optional engine (see ``normalise_sim_args``).

    Only commands whose ``--sim`` option takes a value get their arguments rewritten.
    """

    def parse_args(self, ctx: _click.Context, args: list[str]) -> list[str]:
        """Rewrite ``--sim [ENGINE]`` for the command about to run, then parse as usual."""
        for flag in SIM_FLAGS:
            leaf = _leaf_command(self, ctx, args)
            if flag in args and _sim_takes_value(leaf, flag):
                words = not any(p.param_type_name == "argument" for p in leaf.params)
                args = normalise_sim_args(args, flag=flag, any_word=words)
        return super().parse_args(ctx, args)


# -- negative numbers as values: `poppy motor set 2 goal_position -60` ------------------------

_NEGATIVE_NUMBER = re.compile(r"-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?")


def values_last(params: list[Any], args: list[str]) -> list[str]:
    """``args`` with the options first and the values (arguments) after a ``--``, in their
    order, when a value is a negative number (Click would read ``-60`` as an option ``-6``).

    ``params`` are the command's; an option's own value stays with it (``--baud 1000000``).
    """
    takes_value = {
        name: param.nargs
        for param in params
        if getattr(param, "param_type_name", "") == "option"
        and not param.is_flag
        and not param.count
        for name in (*param.opts, *param.secondary_opts)
    }
    options: list[str] = []
    values: list[str] = []
    index = 0
    while index < len(args):
        token = args[index]
        if token == "--":
            values += args[index + 1 :]
            break
        if _NEGATIVE_NUMBER.fullmatch(token) or not token.startswith("-") or token == "-":
            values.append(token)
        else:
            options.append(token)
            count = takes_value.get(token, 0)  # `--port=X`, `-pX`: the value is in the token
            options += args[index + 1 : index + 1 + count]
            index += count
        index += 1
    if not any(_NEGATIVE_NUMBER.fullmatch(value) for value in values):
        return args
    return [*options, "--", *values]


class NumbersCommand(TyperCommand):
    """A command whose arguments may be negative numbers, with no ``--`` before them."""

    def parse_args(self, ctx: _click.Context, args: list[str]) -> list[str]:
        return super().parse_args(ctx, values_last(self.params, args))
