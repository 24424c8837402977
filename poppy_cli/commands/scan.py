"""`poppy scan`: find every motor on one or all serial ports, over baud rates and protocols."""

from __future__ import annotations

from typing import TYPE_CHECKING

import typer

from poppy_cli.options import (
    MAX_BAUD,
    MIN_BAUD,
    BusPortOpt,
    default_port,
    json_option,
    parse_ids,
    parse_protocols,
)
from poppy_cli.output import (
    EXIT_FAILURE,
    EXIT_INTERRUPTED,
    console,
    counted,
    error_line,
    print_json,
    printable,
    styled,
)
from poppy_cli.port_choice import choose_ports

if TYPE_CHECKING:
    from poppy_core.bus.results import FoundMotor


def found_as_json(motors: list[FoundMotor]) -> list[dict[str, object]]:
    """Scan results as JSON objects: port, baud, protocol, id, model, model_number, firmware."""
    return [
        {
            "port": m.port,
            "baud": m.baudrate,
            "protocol": m.protocol,
            "id": m.id,
            "model": m.model,
            "model_number": m.model_number,
            "firmware": m.firmware,
        }
        for m in motors
    ]


def render_found(motors: list[FoundMotor]) -> None:
    """Print scan results as a Rich table."""
    from rich.table import Table

    table = Table(title=f"{counted(len(motors), 'motor')} found")
    for column in ("port", "baud", "protocol", "id", "model", "firmware"):
        table.add_column(column, justify="right" if column in ("baud", "id") else "left")
    for m in sorted(motors, key=lambda m: (m.port, m.protocol, -m.baudrate, m.id)):
        model = m.model or styled("[yellow]unknown model {}[/]", m.model_number)
        firmware = "-" if m.firmware is None else str(m.firmware)
        table.add_row(m.port, str(m.baudrate), str(m.protocol), str(m.id), model, firmware)
    console.print(table)


def scan(
    port: str | None = BusPortOpt,
    baud: list[int] | None = typer.Option(
        None,
        "--baud",
        "-b",
        help="Baud rate to try (repeat for several). Default: 1000000.",
        min=MIN_BAUD,
        max=MAX_BAUD,
    ),
    all_bauds: bool = typer.Option(
        False, "--all-bauds", help="Try every standard baud rate of each protocol."
    ),
    protocol: str = typer.Option("both", "--protocol", help="Protocol: 1, 2 or both."),
    ids: str = typer.Option("0-253", "--ids", help="IDs to look for, e.g. 0-253 or 1-6,11."),
    json_output: bool = json_option("Print a JSON list instead of a table."),
) -> None:
    """Find the motors on a bus: every ID at the given baud rates, in protocol 1 and/or 2."""
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    from poppy_core.bus.ports import list_ports
    from poppy_core.bus.scan import scan as run_scan

    id_list = parse_ids(ids)
    protocols = parse_protocols(protocol)
    if all_bauds and baud:
        raise typer.BadParameter("give either --baud or --all-bauds, not both")
    baudrates = None if all_bauds else (baud or [1_000_000])
    chosen = default_port(port)
    ports = [chosen] if chosen else choose_ports(list_ports())

    found: list[FoundMotor] = []
    with Progress(
        TextColumn("{task.description}", markup=False),
        BarColumn(),
        TextColumn("{task.completed}/{task.total}"),
        TextColumn("[green]{task.fields[found]} found"),
        TimeElapsedColumn(),
        console=console,
        transient=True,
        disable=json_output or not console.is_terminal,
    ) as bar:
        task = bar.add_task("scanning", total=None, found=0)

        def on_progress(p: object) -> None:
            from poppy_core.bus.results import ScanProgress

            assert isinstance(p, ScanProgress)
            bar.update(
                task,
                total=p.total,
                completed=p.done,
                found=p.found,
                description=printable(f"{p.port} · {p.baudrate} bps · protocol {p.protocol}"),
            )

        try:
            run_scan(
                ports,
                baudrates,
                protocols,
                id_list,
                progress=on_progress,
                on_found=found.append,
            )
        except KeyboardInterrupt:
            bar.stop()
            _show(found, json_output)
            error_line(f"scan interrupted; {counted(len(found), 'motor')} found so far")
            raise typer.Exit(EXIT_INTERRUPTED) from None
    _show(found, json_output)
    if not found:
        where = ", ".join(ports)
        if baudrates is None:  # every rate tried: the rate is not what is wrong
            rates, advice = "all standard rates", "check power, wiring and the adapter's cable"
        else:
            rates, advice = (
                ", ".join(map(str, baudrates)),
                "check power and wiring, or try --all-bauds",
            )
        error_line(f"no motor answered on {where} at {rates} (protocol {protocol}): {advice}")
        raise typer.Exit(EXIT_FAILURE)


def _show(found: list[FoundMotor], json_output: bool) -> None:
    if json_output:
        print_json(found_as_json(found))
    elif found:
        render_found(found)
