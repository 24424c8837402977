"""`poppy doctor`: every check a robot needs, one line each with the command that fixes it."""

from __future__ import annotations

from typing import TYPE_CHECKING

import typer

from poppy_cli.options import BusPortOpt, JsonOpt, ProfileOpt
from poppy_cli.output import EXIT_FAILURE, EXIT_USAGE, console, error_line, print_json, styled

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

    chosen = resolve(profile, None).profile
    if chosen is None:
        error_line("no profile given: pass --profile NAME (see `poppy config list`)")
        raise typer.Exit(EXIT_USAGE)
    config = load_profile(chosen)
    probe = system_probe()
    report = run_doctor(
        config,
        chosen,
        chosen_port(port),
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
