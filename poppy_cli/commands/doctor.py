"""`poppy doctor`: every check a robot needs, one line each with the command that fixes it."""

from __future__ import annotations

from typing import TYPE_CHECKING

import typer

from poppy_cli.options import BusPortOpt, JsonOpt, ProfileOpt
from poppy_cli.output import (
    EXIT_FAILURE,
    EXIT_USAGE,
    console,
    err_console,
    error_line,
    print_json,
    styled,
)

if TYPE_CHECKING:
    from poppy_core.robot.doctor import Check
    from poppy_core.robot.doctor_system import SystemProbe


def system_probe() -> SystemProbe:
    """Where the doctor looks on this machine (tests replace this function with fakes)."""
    from poppy_core.motion.move_library import moves_dir
    from poppy_core.robot.doctor_system import SystemProbe

    return SystemProbe(disk_path=moves_dir())


MARKS = {"pass": "[green]✓ pass[/]", "fail": "[red]✗ FAIL[/]", "skip": "[dim]- skip[/]"}


def _render(check: Check) -> None:
    console.print(styled(MARKS[check.status] + " {}: {}", check.name, check.detail))
    if check.fix and check.status == "fail":
        console.print(styled("    [yellow]fix:[/] {}", check.fix))


def _found_profile(probe: SystemProbe, port: str | None) -> str:
    """The profile of no option, variable or setting: the installed service's, else the one
    whose motors answer on ``port``; else a usage error."""
    from poppy_core.robot.doctor_system import service_profile
    from poppy_core.robot.profile_match import profile_on_port

    found = service_profile(probe)
    if found is not None:
        _say(f"checking {found}, the profile poppy.service serves")
        return found
    if port is not None:
        _say(f"no profile given: looking for a known robot on {port}")
        found = profile_on_port(port)
        if found is not None:
            _say(f"the motors on {port} are those of {found}: checking it")
            return found
    where = f"the motors on {port} are no known robot's" if port else "no bus found"
    error_line(f"no profile given and {where}: pass --profile NAME (see `poppy config list`)")
    raise typer.Exit(EXIT_USAGE)


def _say(message: str) -> None:
    err_console.print(message, style="dim", highlight=False, markup=False)


def doctor(
    profile: str | None = ProfileOpt,
    port: str | None = BusPortOpt,
    url: str | None = typer.Option(
        None,
        "--url",
        help="The robot's page, checked when poppy.service is installed "
        "(default: http://NAME.local/, NAME as the service names the robot, else poppy).",
    ),
    json_output: bool = JsonOpt,
) -> None:
    """Check the adapter, latency timer, every motor, camera, service, page and disk.

    One line per check, with the command that fixes a failure; exit 0 only when none fails
    (a check that does not apply here is skipped, with the reason).
    """
    from poppy_cli.commands.setup import chosen_port
    from poppy_cli.settings import resolve
    from poppy_core.robot.doctor_system import run_doctor
    from poppy_core.robot.profiles import load_profile

    probe = system_probe()
    bus_port = chosen_port(port)
    chosen = resolve(profile, None).profile or _found_profile(probe, bus_port)
    config = load_profile(chosen)
    report = run_doctor(
        config,
        chosen,
        bus_port,
        page_url=url,
        probe=probe,
        progress=None if json_output else _render,
    )
    if json_output:
        print_json(report.as_dict())
    else:
        failed = sum(1 for c in report.checks if c.status == "fail")
        console.print(
            styled("[green]all checks pass[/]")
            if report.ok
            else styled("[red]{} check(s) failed[/]", failed)
        )
    if not report.ok:
        raise typer.Exit(EXIT_FAILURE)
