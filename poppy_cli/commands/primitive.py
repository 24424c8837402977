"""`poppy primitive ...`: list a robot's primitives and run one, with a live status line."""

from __future__ import annotations

import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

import typer

from poppy_cli import complete
from poppy_cli.options import (
    ConfigOpt,
    JsonOpt,
    PortOpt,
    ProfileOpt,
    RemoteOpt,
    SimOpt,
    duration_option,
)
from poppy_cli.output import EXIT_FAILURE, console, error_line, print_json
from poppy_cli.robots import build_robot

if TYPE_CHECKING:
    from rich.table import Table

    from poppy_core.motion import Primitive
    from poppy_core.robot import Robot

app = typer.Typer(
    help="Run behaviours on a robot: sinus, square, postures, position watcher...",
    no_args_is_help=True,
)

REFRESH_S = 0.1


def robot_primitives(robot: Robot) -> dict[str, Primitive]:
    """The primitives available on ``robot``: the built-ins plus those attached to it."""
    from poppy_core.motion import attach_builtins, attached_primitives

    attach_builtins(robot)
    return attached_primitives(robot)


def _find(primitives: dict[str, Primitive], name: str) -> tuple[str, Primitive]:
    from poppy_core.errors import ConfigError

    wanted = name.strip().lower().replace("-", "_")
    for key, primitive in primitives.items():
        if wanted in (key.lower(), type(primitive).__name__.lower()):
            return key, primitive
    raise ConfigError(
        f"no primitive {name!r} (primitives: {', '.join(primitives)})", field=name, value=name
    )


def _settings(pairs: list[str]) -> list[tuple[str, str]]:
    out = []
    for pair in pairs:
        key, sep, value = pair.partition("=")
        if not sep or not key.strip():
            raise typer.BadParameter(f"{pair!r} is not PROPERTY=VALUE (e.g. amplitude=20)")
        out.append((key.strip(), value.strip()))
    return out


def _text(value: Any) -> str:
    if isinstance(value, float):
        return f"{value:g}"
    if isinstance(value, list | tuple):
        return ",".join(_text(v) for v in value)
    if isinstance(value, dict):
        return ",".join(f"{k}={_text(v)}" for k, v in value.items())
    return str(value)


def primitives_table(primitives: dict[str, Primitive]) -> Table:
    """A Rich table of the primitives: class, state, properties, error."""
    from rich.table import Table

    table = Table(title="primitives")
    for column in ("name", "class", "state", "properties", "error"):
        table.add_column(column)
    for name, primitive in primitives.items():
        props = "\n".join(f"{k}={_text(v)}" for k, v in primitive.property_values().items())
        error = primitive.error.one_line if primitive.error is not None else ""
        table.add_row(name, type(primitive).__name__, primitive.state, props, error)
    return table


@app.command("list")
def list_primitives(
    profile: str | None = ProfileOpt,
    config_file: Path | None = ConfigOpt,
    port: str | None = PortOpt,
    sim: str | None = SimOpt,
    json_output: bool = JsonOpt,
    remote: str | None = RemoteOpt,
) -> None:
    """List the primitives of a robot with their state, properties and last error."""
    if remote:
        from poppy_cli.commands.remote_runs import list_remote

        list_remote(remote, json_output)
        return
    with build_robot(profile, config_file, port, sim) as robot:
        primitives = robot_primitives(robot)
        if json_output:
            print_json([{"name": name, **p.describe()} for name, p in primitives.items()])
            return
        console.print(primitives_table(primitives))


def _status(name: str, primitive: Primitive) -> str:
    hint = "  (Ctrl-C to stop)" if primitive.is_alive() else ""
    return f"{name}: {primitive.state}  {primitive.elapsed_time:.1f} s{hint}"


def state_debug() -> bool:
    """True with ``poppy --debug``."""
    from poppy_cli import state

    return state.debug


def _quiet_tracebacks() -> None:
    """Keep a failed primitive's logged traceback off the terminal unless logs are on."""
    import logging

    if not state_debug() and not logging.getLogger().handlers:
        logging.getLogger("poppy_core.motion.primitive").addHandler(logging.NullHandler())


def _wait(primitive: Primitive, duration: float | None, on_tick: Any) -> None:
    deadline = None if duration is None else time.monotonic() + duration
    while primitive.is_alive():
        if deadline is not None and time.monotonic() >= deadline:
            break
        on_tick()
        time.sleep(REFRESH_S)  # not wait_to_stop: a failure is reported below, from .error


@app.command("run")
def run(
    name: str = typer.Argument(
        ..., help="Primitive name (see `poppy primitive list`).", autocompletion=complete.primitives
    ),
    duration: float | None = duration_option(
        None, "Stop after this many seconds (default: Ctrl-C)."
    ),
    settings: list[str] | None = typer.Option(
        None, "--set", help="PROPERTY=VALUE before starting, e.g. --set amplitude=20 (repeat)."
    ),
    stiff: bool = typer.Option(
        True, "--stiff/--keep-compliance", help="Turn the torque on before starting."
    ),
    profile: str | None = ProfileOpt,
    config_file: Path | None = ConfigOpt,
    port: str | None = PortOpt,
    sim: str | None = SimOpt,
    json_output: bool = JsonOpt,
    remote: str | None = RemoteOpt,
) -> None:
    """Start a primitive, show its state live, stop it after --duration or on Ctrl-C.

    Exits with 1 and the error's line when the primitive fails.
    """
    pairs = _settings(settings or [])
    if remote:
        from poppy_cli.commands.remote_runs import run_remote

        run_remote(remote, name, duration, pairs, stiff, json_output)
        return
    _quiet_tracebacks()
    with build_robot(profile, config_file, port, sim) as robot:
        key, primitive = _find(robot_primitives(robot), name)
        for prop, value in pairs:
            primitive.set_property(prop, value)
        if stiff:
            robot.compliant = False
        primitive.start()
        interrupted = False
        try:
            if json_output or not console.is_terminal:
                _wait(primitive, duration, lambda: None)
            else:
                from rich.live import Live

                with Live(console=console, refresh_per_second=10) as live:
                    _wait(primitive, duration, lambda: live.update(_status(key, primitive)))
                    primitive.halt()
                    live.update(_status(key, primitive))
        except KeyboardInterrupt:
            interrupted = True
        primitive.halt()  # its failure, if any, is reported below
        report = {"name": key, "interrupted": interrupted, **primitive.describe()}
    if json_output:
        print_json(report)
    elif not console.is_terminal:
        console.print(_status(key, primitive))
    if primitive.error is not None:
        hint = "" if state_debug() else " (run with --debug for the traceback)"
        error_line(f"primitive {key} failed: {primitive.error.one_line}{hint}")
        raise typer.Exit(EXIT_FAILURE)
