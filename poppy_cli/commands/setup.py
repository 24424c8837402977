"""`poppy setup motors`: set a kit's motors up one at a time (ID, rate, return delay, limits)."""

from __future__ import annotations

import sys
from typing import TYPE_CHECKING

import typer

from poppy_cli.options import BusPortOpt, JsonOpt, ProfileOpt
from poppy_cli.output import (
    EXIT_FAILURE,
    EXIT_USAGE,
    err_console,
    error_line,
    print_json,
    styled,
)

if TYPE_CHECKING:
    from poppy_core.robot.guided_setup import GuidedSetup, MotorTarget, StepOutcome

app = typer.Typer(
    help="Set a robot up from its kit: each motor's ID, baud rate, return delay and limits.",
    no_args_is_help=True,
)


def chosen_port(port: str | None) -> str | None:
    """The port given (option, POPPY_PORT, settings), else the one recognised adapter."""
    from poppy_cli.settings import resolve
    from poppy_core.bus.ports import list_ports

    given = resolve(None, port).port
    if given is not None:
        return given
    adapters = [p.device for p in list_ports() if p.adapter is not None]
    return adapters[0] if len(adapters) == 1 else None


def _say(message: str) -> None:
    err_console.print(styled("[dim]· {}[/]", message))


def _wait_for_enter(target: MotorTarget) -> bool:
    """Show the motor's prompt and wait for Enter; False when the input has ended."""
    from poppy_cli.prompts import interactive, interruptible, read_line

    err_console.print(styled("[bold]{}[/]", target.prompt))
    if interactive():
        with interruptible():
            line = read_line()
    else:
        line = sys.stdin.readline()
    return line != ""


def _set_up_one(flow: GuidedSetup, target: MotorTarget, json_output: bool) -> StepOutcome:
    """Prompt for ``target`` until it is set up; on a terminal a failure asks again."""
    from poppy_cli.prompts import interactive
    from poppy_core.errors import SetupError

    while True:
        if not _wait_for_enter(target):
            error_line(
                f"input ended before {target.name} was set up; go on with "
                f"`poppy setup motors --motors {target.name},...`"
            )
            raise typer.Exit(EXIT_FAILURE)
        try:
            return flow.set_up(target, None if json_output else _say)
        except SetupError as exc:
            error_line(str(exc))
            if not interactive():
                raise typer.Exit(EXIT_FAILURE) from None


@app.command("motors")
def motors(
    profile: str | None = ProfileOpt,
    port: str | None = BusPortOpt,
    only: str | None = typer.Option(
        None, "--motors", "-m", help="Set up only these motors, e.g. m3 or m3,m4 (default: all)."
    ),
    json_output: bool = JsonOpt,
) -> None:
    """Set each motor of a kit up, one at a time on the bus: ID, rate, return delay, limits.

    For each motor in the profile's order: "plug only m3 (XL-320) on the bus and press Enter";
    the one motor found (any ID, rate, protocol) gets the profile's settings, verified. A
    motor already right is left as it is. `--json`: a list of what each step did.
    """
    from poppy_cli.settings import resolve
    from poppy_core.robot.guided_setup import GuidedSetup
    from poppy_core.robot.profiles import load_profile

    name = resolve(profile, None).profile
    if name is None:
        error_line("no profile given: pass --profile NAME (see `poppy config list`)")
        raise typer.Exit(EXIT_USAGE)
    bus_port = chosen_port(port)
    if bus_port is None:
        error_line("no port given and not one recognised adapter: pass --port (see `poppy ports`)")
        raise typer.Exit(EXIT_USAGE)
    names = [n.strip() for n in only.split(",") if n.strip()] if only else None
    flow = GuidedSetup(load_profile(name), bus_port, names)
    if not json_output:
        listed = ", ".join(f"{t.name} ({t.model}, ID {t.id})" for t in flow.targets)
        err_console.print(
            f"setting up {len(flow.targets)} motor(s) on {bus_port}: {listed}",
            markup=False,
            highlight=False,
        )
    outcomes = []
    for target in flow.targets:
        outcome = _set_up_one(flow, target, json_output)
        outcomes.append(outcome)
        if not json_output:
            err_console.print(styled("[green]✓[/] {}", outcome.summary()))
    if json_output:
        print_json([o.as_dict() for o in outcomes])
    else:
        err_console.print(
            f"done: check the robot with `poppy doctor --profile {name}`", markup=False
        )
