"""`poppy motor set-id|set-baudrate|set-return-delay|angle-limits|reset|reboot|factory-reset`."""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import typer

from poppy_cli.commands.motor import app, print_setup, require_port, setup_record
from poppy_cli.options import (
    MAX_BAUD,
    MIN_BAUD,
    BaudOpt,
    BusPortOpt,
    JsonOpt,
    NumbersCommand,
    ProtoOpt,
    finite,
    parse_ids,
)

if TYPE_CHECKING:
    from poppy_core.bus.dxlbus import DxlBus
    from poppy_core.bus.results import SetupResult

__all__ = ["app"]
from poppy_cli.connect import open_bus
from poppy_cli.output import EXIT_USAGE, console, error_line, styled


def _say(message: str) -> None:
    console.print(styled("[dim]· {}[/]", message))


def _run_setup(
    port: str | None,
    motor_id: int,
    baud: int | None,
    protocol: int | None,
    json_output: bool,
    operation: Callable[[DxlBus, Callable[[str], None] | None], SetupResult],
) -> None:
    """Open the bus where ``motor_id`` answers, run one setup operation, print its result."""
    with open_bus(require_port(port), [motor_id], baud, protocol) as bus:
        result = operation(bus, None if json_output else _say)
    print_setup(result, json_output)


@app.command("set-id")
def set_id(
    motor_id: int = typer.Argument(..., help="Current ID.", min=0, max=253),
    new_id: int = typer.Argument(..., help="New ID.", min=0, max=253),
    port: str | None = BusPortOpt,
    baud: int | None = BaudOpt,
    protocol: int | None = ProtoOpt,
    json_output: bool = JsonOpt,
) -> None:
    """Give a motor a new ID (refused if the ID is taken; verified afterwards)."""
    from poppy_core.bus.setup import change_id

    _run_setup(
        port,
        motor_id,
        baud,
        protocol,
        json_output,
        lambda bus, say: change_id(bus, motor_id, new_id, progress=say),
    )


@app.command("set-baudrate")
def set_baudrate(
    motor_id: int = typer.Argument(..., help="Motor ID.", min=0, max=253),
    rate: int = typer.Argument(
        ...,
        metavar="BPS",
        help="New baud rate in bps, e.g. 1000000.",
        min=MIN_BAUD,
        max=MAX_BAUD,
    ),
    port: str | None = BusPortOpt,
    baud: int | None = BaudOpt,
    protocol: int | None = ProtoOpt,
    json_output: bool = JsonOpt,
) -> None:
    """Change a motor's baud rate; it is checked at the new rate (and found again if lost)."""
    from poppy_core.bus.setup import change_baudrate

    _run_setup(
        port,
        motor_id,
        baud,
        protocol,
        json_output,
        lambda bus, say: change_baudrate(bus, motor_id, rate, progress=say),
    )


def _run_each(
    port: str | None,
    ids: str,
    baud: int | None,
    protocol: int | None,
    json_output: bool,
    operation: Callable[[DxlBus, int, Callable[[str], None] | None], SetupResult],
) -> None:
    """Open the bus where the ``ids`` answer and run one setup operation on each, in order;
    print each result (``--json``: a list of them, whatever the number of IDs)."""
    from poppy_cli.output import print_json

    id_list = parse_ids(ids)
    results = []
    with open_bus(require_port(port), id_list, baud, protocol) as bus:
        for motor_id in id_list:
            result = operation(bus, motor_id, None if json_output else _say)
            results.append(result)
            if not json_output:
                print_setup(result, json_output=False)
    if json_output:
        print_json([setup_record(result) for result in results])


@app.command("set-return-delay", cls=NumbersCommand)
def set_return_delay(
    ids: str = typer.Argument(..., help="Motor ID(s): 3, or 1-6, or 1,3,5."),
    delay_us: float = typer.Argument(
        ..., help="Return delay in µs (0 for a fast bus).", callback=finite
    ),
    port: str | None = BusPortOpt,
    baud: int | None = BaudOpt,
    protocol: int | None = ProtoOpt,
    json_output: bool = JsonOpt,
) -> None:
    """Set the return delay time (µs); Poppy robots use 0: `poppy motor set-return-delay 1-6 0`.

    The return delay is in the EEPROM, which protocol 2 motors (XL-320, X series) lock while
    their torque is on: a stiff motor is made compliant for the write and stiff again after.
    """
    from poppy_core.bus.setup import set_return_delay as run

    _run_each(
        port,
        ids,
        baud,
        protocol,
        json_output,
        lambda bus, motor_id, say: run(bus, motor_id, delay_us, progress=say),
    )


@app.command("angle-limits", cls=NumbersCommand)
def angle_limits(
    ids: str = typer.Argument(..., help="Motor ID(s): 3, or 1-6, or 1,3,5."),
    min_deg: float | None = typer.Argument(None, help="Lower limit in degrees.", callback=finite),
    max_deg: float | None = typer.Argument(None, help="Upper limit in degrees.", callback=finite),
    port: str | None = BusPortOpt,
    baud: int | None = BaudOpt,
    protocol: int | None = ProtoOpt,
    json_output: bool = JsonOpt,
) -> None:
    """Show the angle limits, or set them: `poppy motor angle-limits 3 -90 90`.

    `--json`: a list of {id, min, max} (or of setup results), whatever the number of IDs.
    """
    from poppy_cli.connect import ping_model
    from poppy_cli.output import fmt_value, print_json
    from poppy_core.bus.setup import set_angle_limits

    if (min_deg is None) != (max_deg is None):
        error_line("give both limits (MIN MAX), or none to read them")
        raise typer.Exit(EXIT_USAGE)
    if min_deg is not None and max_deg is not None:
        low, high = min_deg, max_deg
        _run_each(
            port,
            ids,
            baud,
            protocol,
            json_output,
            lambda bus, motor_id, say: set_angle_limits(bus, motor_id, low, high, progress=say),
        )
        return
    id_list = parse_ids(ids)
    rows = []
    with open_bus(require_port(port), id_list, baud, protocol) as bus:
        for motor_id in id_list:
            model = ping_model(bus, motor_id).model
            assert model is not None
            rows.append(
                {
                    "id": motor_id,
                    "min": bus.read_register(motor_id, model, "min_position_limit"),
                    "max": bus.read_register(motor_id, model, "max_position_limit"),
                }
            )
    if json_output:
        print_json(rows)
        return
    for row in rows:
        console.print(
            f"motor {row['id']}: {fmt_value(row['min'], 'deg')} .. {fmt_value(row['max'], 'deg')}"
        )


@app.command("reboot")
def reboot(
    ids: str = typer.Argument(..., help="Motor ID(s): 3, or 1-6, or 1,3,5."),
    port: str | None = BusPortOpt,
    baud: int | None = BaudOpt,
    protocol: int | None = ProtoOpt,
    json_output: bool = JsonOpt,
) -> None:
    """Reboot motors (clears a hardware alarm) and wait until each answers again."""
    from poppy_core.bus.setup import reboot as run

    _run_each(
        port,
        ids,
        baud,
        protocol,
        json_output,
        lambda bus, motor_id, say: run(bus, motor_id, progress=say),
    )


@app.command("factory-reset")
def factory_reset(
    motor_id: int = typer.Argument(..., help="Motor ID.", min=0, max=253),
    reset_id: bool = typer.Option(
        False, "--reset-id", help="Also reset the ID to the factory one."
    ),
    reset_baudrate: bool = typer.Option(
        False, "--reset-baudrate", help="Also reset the baud rate to the factory one."
    ),
    yes: bool = typer.Option(False, "--yes", "-y", help="Do not ask for confirmation."),
    port: str | None = BusPortOpt,
    baud: int | None = BaudOpt,
    protocol: int | None = ProtoOpt,
    json_output: bool = JsonOpt,
) -> None:
    """Restore the factory control table (keeps ID and baud rate unless told otherwise)."""
    from poppy_core.bus.setup_reset import factory_reset as run

    if not yes:
        from poppy_cli.prompts import require_yes

        require_yes(
            f"Reset motor {motor_id} to its factory settings?", declined="factory reset cancelled"
        )
    _run_setup(
        port,
        motor_id,
        baud,
        protocol,
        json_output,
        lambda bus, say: run(
            bus, motor_id, keep_id=not reset_id, keep_baudrate=not reset_baudrate, progress=say
        ),
    )


@app.command("reset")
def reset(
    motor_id: int = typer.Argument(
        ..., help="Current motor ID (a new motor is ID 1).", min=0, max=253
    ),
    target_id: int = typer.Argument(..., help="The ID the motor must have.", min=0, max=253),
    model: str | None = typer.Option(
        None, "--model", help="Expected model (e.g. MX-28); refused if the motor differs."
    ),
    rate: int = typer.Option(
        1_000_000,
        "--target-baud",
        help="Baud rate to give the motor (Poppy: 1000000).",
        min=MIN_BAUD,
        max=MAX_BAUD,
    ),
    limits: str | None = typer.Option(
        None, "--angle-limits", help="Angle limits MIN,MAX in degrees, e.g. -150,150."
    ),
    zero: bool = typer.Option(False, "--zero", help="Move the motor to 0° afterwards."),
    port: str | None = BusPortOpt,
    baud: int | None = BaudOpt,
    protocol: int | None = ProtoOpt,
    json_output: bool = JsonOpt,
) -> None:
    """Prepare a motor for a Poppy robot (the old poppy-reset-motor): ID, 1 Mbps, delay 0."""
    from poppy_core.bus.setup_reset import reset_motor

    angle_limits = None
    if limits is not None:
        try:
            low, high = (float(v) for v in limits.split(","))
        except ValueError:
            raise typer.BadParameter(f"{limits!r} is not MIN,MAX, e.g. -150,150") from None
        angle_limits = (low, high)
    _run_setup(
        port,
        motor_id,
        baud,
        protocol,
        json_output,
        lambda bus, say: reset_motor(
            bus,
            motor_id,
            target_id=target_id,
            model=model,
            baudrate=rate,
            angle_limits=angle_limits,
            go_to_zero=zero,
            progress=say,
        ),
    )
