"""`poppy config ...`: check, convert, show, list and generate robot configs."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import typer

from poppy_cli import complete
from poppy_cli.options import BaudOpt, BusPortOpt, JsonOpt, ProtoOpt, default_port, json_option
from poppy_cli.output import (
    EXIT_FAILURE,
    EXIT_USAGE,
    console,
    counted,
    error_line,
    fmt_value,
    plain,
    print_json,
    styled,
)

if TYPE_CHECKING:
    from poppy_core.bus.results import FoundMotor
    from poppy_core.robot import RobotConfig

app = typer.Typer(
    help="Robot configs and profiles: validate, convert, show, list, generate from a bus.",
    no_args_is_help=True,
)


def _counts(config: RobotConfig) -> str:
    return ", ".join(
        counted(len(things), word)
        for things, word in (
            (config.motors, "motor"),
            (config.controllers, "controller"),
            (config.motorgroups, "group"),
        )
    )


@app.command("validate")
def validate(file: Path = typer.Argument(..., help="Config file (JSON or YAML).")) -> None:
    """Check a config file; a problem is reported as one line naming the field."""
    from poppy_core.robot import load_config

    config = load_config(file)
    console.print(styled("[green]ok[/] {}: {}", file, _counts(config)))


ForceOpt = typer.Option(False, "--force", "-f", help="Replace an existing file.")


@app.command("convert")
def convert(
    source: Path = typer.Argument(..., help="Config to read (JSON or YAML)."),
    target: Path = typer.Argument(
        ..., help="File to write (.json or .yaml/.yml picks the format), or a folder."
    ),
    force: bool = ForceOpt,
) -> None:
    """Convert a config between JSON and YAML (the format follows TARGET's extension).

    Into a folder, the file keeps SOURCE's name with the other format's extension. An existing
    file is replaced only with --force; a folder, a link or a device never.
    """
    from poppy_core.files import output_path
    from poppy_core.robot import dump_config, load_config

    other = ".yaml" if source.suffix.lower() == ".json" else ".json"
    chosen = output_path(target, default_name=f"{source.stem}{other}", replace=force)
    if chosen.suffix.lower() not in (".json", ".yaml", ".yml"):
        error_line(f"{chosen}: the extension must be .json, .yaml or .yml")
        raise typer.Exit(EXIT_USAGE)
    config = load_config(source)
    written = dump_config(config, chosen, replace=force)
    console.print(f"wrote {written}: {_counts(config)}")


@app.command("show")
def show(
    profile: str = typer.Argument(
        ...,
        help="Profile name (see `poppy config list`) or a file.",
        autocompletion=complete.profiles,
    ),
    json_output: bool = json_option("Print the config as JSON."),
    yaml_output: bool = typer.Option(False, "--yaml", help="Print the config as YAML."),
) -> None:
    """Show a profile's (or config file's) motors, controllers and groups."""
    from rich.table import Table

    from poppy_core.robot import config_to_text, load_config, load_profile

    path = Path(profile)
    config = load_config(path) if path.is_file() else load_profile(profile)
    if json_output:
        print_json(config.to_dict())
        return
    if yaml_output:
        console.print(config_to_text(config, "yaml"), markup=False, end="")
        return
    # A line of its own (not the table's title): a long path is never wrapped to the table's width.
    console.print(styled("[bold]{}[/]: {}", profile, _counts(config)), soft_wrap=True)
    table = Table()
    for column in ("motor", "id", "model", "orientation", "offset", "limits", "controller"):
        table.add_column(column, justify="right" if column in ("id", "offset") else "left")
    for name, motor in config.motors.items():
        low, high = motor.angle_limit
        table.add_row(
            name,
            str(motor.id),
            motor.type,
            motor.orientation,
            fmt_value(motor.offset, "°"),
            f"{fmt_value(low)}° … {fmt_value(high)}°",
            config.controller_of(name) or "-",
        )
    console.print(table)
    for name, controller in config.controllers.items():
        console.print(
            styled(
                "controller [bold]{}[/]: port {}, protocol {}, {} bps",
                name,
                controller.port,
                controller.protocol,
                controller.baudrate,
            )
        )
    for name in config.motorgroups:
        console.print(styled("group [bold]{}[/]: {}", name, ", ".join(config.resolve_group(name))))


@app.command("list")
def list_cmd(
    json_output: bool = JsonOpt,
) -> None:
    """List the installed and user profiles."""
    from rich.table import Table

    from poppy_core.robot import list_profiles

    profiles = list_profiles()
    if json_output:
        print_json(
            [
                {
                    "name": p.name,
                    "kind": p.kind,
                    "description": p.description,
                    "user": p.user,
                    "file": str(p.file),
                }
                for p in profiles
            ]
        )
        return
    table = Table(title="robot profiles")
    for column in ("name", "origin", "description"):
        table.add_column(column)
    for p in profiles:
        table.add_row(p.name, styled("[bold]user[/]") if p.user else "installed", p.description)
    console.print(table)


def build_config(found: list[FoundMotor], prefix: str) -> dict[str, Any]:
    """A config mapping for the motors found: one controller per port and protocol."""
    from poppy_core.bus import DxlBus
    from poppy_core.models import model_by_name
    from poppy_core.protocol import protocol_for

    controllers: dict[str, Any] = {}
    motors: dict[str, Any] = {}
    groups = sorted({(f.port, f.protocol, f.baudrate) for f in found})
    for index, (device, protocol, baudrate) in enumerate(groups, start=1):
        chosen = sorted(
            (f for f in found if (f.port, f.protocol, f.baudrate) == (device, protocol, baudrate)),
            key=lambda f: f.id,
        )
        names = [f"{prefix}{f.id}" for f in chosen]
        controllers[f"controller_{index}"] = {
            "port": device,
            "protocol": protocol,
            "baudrate": baudrate,
            "sync_read": protocol_for(protocol).has_sync_read,
            "attached_motors": names,
        }
        with DxlBus(device, baudrate, protocol) as bus:
            for name, motor in zip(names, chosen, strict=True):
                model = model_by_name(str(motor.model))
                low = bus.read_register(motor.id, model, "min_position_limit")
                high = bus.read_register(motor.id, model, "max_position_limit")
                if not isinstance(low, float) or not isinstance(high, float) or not low < high:
                    span = model.position_range_deg / 2
                    low, high = -span, span
                motors[name] = {
                    "id": motor.id,
                    "type": model.name,
                    "orientation": "direct",
                    "offset": 0.0,
                    "angle_limit": [round(low, 2), round(high, 2)],
                }
    return {"controllers": controllers, "motorgroups": {}, "motors": motors}


@app.command("generate")
def generate(
    output: Path = typer.Option(
        ..., "--output", "-o", help="File to write (.json or .yaml), or a folder (robot.yaml)."
    ),
    port: str | None = BusPortOpt,
    baud: int | None = BaudOpt,
    protocol: int | None = ProtoOpt,
    name: str = typer.Option("m", "--prefix", help="Motor name prefix: <prefix><ID>."),
    force: bool = ForceOpt,
) -> None:
    """Scan a bus and write a config of the motors found (limits read from the motors)."""
    from poppy_core.bus import scan as run_scan
    from poppy_core.files import output_path
    from poppy_core.robot import RobotConfig, dump_config

    if output.suffix.lower() not in (".json", ".yaml", ".yml") and not output.is_dir():
        error_line(f"{output}: the extension must be .json, .yaml or .yml")
        raise typer.Exit(EXIT_USAGE)
    output = output_path(output, default_name="robot.yaml", replace=force)  # before the scan
    chosen_port = default_port(port)
    if not chosen_port:
        error_line("no port given: pass --port (see `poppy ports`) or set POPPY_PORT")
        raise typer.Exit(EXIT_USAGE)
    baudrates = [baud] if baud is not None else None
    protocols = [protocol] if protocol is not None else [1, 2]
    with console.status(plain(f"scanning {chosen_port}…")):
        found = [f for f in run_scan(chosen_port, baudrates, protocols) if f.model is not None]
    if not found:
        error_line(f"no known motor found on {chosen_port}")
        raise typer.Exit(EXIT_FAILURE)
    config = RobotConfig.from_dict(build_config(found, name), source="generate")
    written = dump_config(config, output, replace=force)
    console.print(f"wrote {written}: {_counts(config)}")


def _register_settings() -> None:
    from poppy_cli.commands import config_settings

    config_settings.register(app)


_register_settings()
