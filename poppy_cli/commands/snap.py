"""`poppy snap`: the Poppy blocks and example projects as Snap! XML; Snap! downloaded once."""

from __future__ import annotations

from pathlib import Path

import typer

from poppy_cli.commands.snap_download import download
from poppy_cli.options import ConfigOpt, ProfileOpt
from poppy_cli.output import EXIT_USAGE, console, error_line

app = typer.Typer(
    help="Snap! files generated for a robot: the Poppy blocks and example projects.",
    no_args_is_help=True,
)

HostOpt = typer.Option(
    "127.0.0.1", "--host", help="Address of the robot's Snap! server that the blocks call."
)
SnapPortOpt = typer.Option(6969, "--snap-port", min=1, max=65535, help="Its port.")
ForceOpt = typer.Option(False, "--force", "-f", help="Replace an existing file.")


def _write(
    name: str,
    output: Path,
    profile: str | None,
    config_file: Path | None,
    host: str,
    port: int,
    force: bool,
) -> None:
    from poppy_cli.robots import build_robot
    from poppy_core.files import output_path, write_file
    from poppy_core.server import RobotService
    from poppy_core.server.snap import robot_facts
    from poppy_core.server.snap.examples import document, project_names

    if name not in project_names():
        error_line(f"no Snap! project {name!r}: choose one of {', '.join(project_names())}")
        raise typer.Exit(EXIT_USAGE)
    target = output_path(output, default_name=f"{name}.xml", replace=force)
    # a virtual robot of that config gives the names (motors, groups, behaviours, chains)
    with build_robot(profile, config_file, None, "ideal") as robot:
        service = RobotService(robot)
        try:
            body = document(name, robot_facts(service), host, port)
        finally:
            service.close()
    assert body is not None
    written = write_file(target, body, replace=force)
    console.print(f"wrote {written} ({name}, for http://{host}:{port})")


@app.command("blocks")
def blocks(
    output: Path = typer.Option(
        ..., "--output", "-o", help="File to write, or a folder (poppy-blocks.xml)."
    ),
    lang: str = typer.Option("en", "--lang", help="Language of the blocks: en or fr."),
    profile: str | None = ProfileOpt,
    config_file: Path | None = ConfigOpt,
    host: str = HostOpt,
    snap_port: int = SnapPortOpt,
    force: bool = ForceOpt,
) -> None:
    """Write the Poppy blocks for this robot (open the file in Snap!, or drag it onto Snap!)."""
    if lang not in ("en", "fr"):
        error_line(f"--lang {lang!r}: choose en or fr")
        raise typer.Exit(EXIT_USAGE)
    name = "poppy-blocks-fr" if lang == "fr" else "poppy-blocks"
    _write(name, output, profile, config_file, host, snap_port, force)


@app.command("project")
def project(
    name: str = typer.Argument(
        ..., help="first-steps, record-replay, ik-drawing (add -fr for French)."
    ),
    output: Path = typer.Option(..., "--output", "-o", help="File to write, or a folder."),
    profile: str | None = ProfileOpt,
    config_file: Path | None = ConfigOpt,
    host: str = HostOpt,
    snap_port: int = SnapPortOpt,
    force: bool = ForceOpt,
) -> None:
    """Write an example Snap! project for this robot (blocks included)."""
    _write(name, output, profile, config_file, host, snap_port, force)


app.command("download")(download)
