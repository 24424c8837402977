"""`poppy motor ...`: read, write and set up one motor (or a few) on a bus, in SI units."""

from __future__ import annotations

from typing import TYPE_CHECKING

import typer

from poppy_cli import complete
from poppy_cli.connect import open_bus, ping_model
from poppy_cli.options import (
    BaudOpt,
    BusPortOpt,
    JsonOpt,
    NumbersCommand,
    ProtoOpt,
    default_port,
    format_ids,
    parse_ids,
)
from poppy_cli.output import EXIT_USAGE, console, error_line, fmt_value, print_json, styled

if TYPE_CHECKING:
    from poppy_core.bus.results import SetupResult
    from poppy_core.models import Register, SIValue

app = typer.Typer(
    help="Read, write and set up motors: IDs, baud rates, limits, torque, LED, reset.",
    no_args_is_help=True,
)


def require_port(port: str | None) -> str:
    chosen = default_port(port)
    if not chosen:
        error_line("no port given: pass --port (see `poppy ports`) or set POPPY_PORT")
        raise typer.Exit(EXIT_USAGE)
    return chosen


def parse_value(register: Register, text: str) -> SIValue:
    """Turn command-line text into the SI value ``register.from_si`` expects (the XL-320 LED
    takes a colour: ``on`` is white, all three LEDs)."""
    return register.parse(text)


def setup_record(result: SetupResult) -> dict[str, object]:
    """A setup result as JSON."""
    return {
        "operation": result.operation,
        "port": result.port,
        "id": result.motor_id,
        "baud": result.baudrate,
        "protocol": result.protocol,
        "changes": {k: list(v) for k, v in result.changes.items()},
        "verified": result.verified,
        "notes": result.notes,
    }


def print_setup(result: SetupResult, json_output: bool) -> None:
    if json_output:
        print_json(setup_record(result))
        return
    for name, (old, new) in result.changes.items():
        console.print(styled("{}: {} → [bold]{}[/]", name, fmt_value(old), fmt_value(new)))
    for note in result.notes:
        console.print(styled("[dim]{}[/]", note))
    check = "[green]verified[/]" if result.verified else "[yellow]not verified[/]"
    console.print(
        styled(
            "motor {} on {} at {} bps (protocol {}): " + check,
            result.motor_id,
            result.port,
            result.baudrate,
            result.protocol,
        )
    )


@app.command("info")
def info(
    motor_id: int = typer.Argument(..., help="Motor ID.", min=0, max=253),
    port: str | None = BusPortOpt,
    baud: int | None = BaudOpt,
    protocol: int | None = ProtoOpt,
    json_output: bool = JsonOpt,
) -> None:
    """Show a motor's model and its whole control table in SI units."""
    from rich.table import Table

    with open_bus(require_port(port), [motor_id], baud, protocol) as bus:
        result = ping_model(bus, motor_id)
        model = result.model
        assert model is not None
        raw = bus.read(motor_id, 0, model.table_size)
    rows = []
    for reg in sorted(model.registers.values(), key=lambda r: r.address):
        rows.append((reg, reg.decode_si(raw, start=0)))
    if json_output:
        print_json(
            {
                "id": motor_id,
                "model": model.name,
                "model_number": result.model_number,
                "firmware": result.firmware,
                "port": bus.port,
                "baud": bus.baudrate,
                "protocol": bus.protocol,
                "registers": [
                    {
                        "name": reg.name,
                        "value": value,
                        "unit": reg.unit,
                        "address": reg.address,
                        "access": reg.access,
                        "memory": reg.memory,
                    }
                    for reg, value in rows
                ],
            }
        )
        return
    table = Table(
        title=f"motor {motor_id}: {model.name} (firmware {result.firmware}) "
        f"on {bus.port} at {bus.baudrate} bps, protocol {bus.protocol}"
    )
    for column in ("address", "register", "value", "access", "memory"):
        table.add_column(column, justify="right" if column == "address" else "left")
    for reg, value in rows:
        access = "read-only" if not reg.writable else "rw"
        table.add_row(str(reg.address), reg.name, fmt_value(value, reg.unit), access, reg.memory)
    console.print(table)


@app.command("get")
def get(
    ids: str = typer.Argument(..., help="Motor ID(s): 11, or 1-6, or 1,3,5."),
    registers: list[str] = typer.Argument(
        ..., help="Register name(s), e.g. present_position.", autocompletion=complete.registers
    ),
    port: str | None = BusPortOpt,
    baud: int | None = BaudOpt,
    protocol: int | None = ProtoOpt,
    json_output: bool = JsonOpt,
) -> None:
    """Read registers in SI units: `poppy motor get 11 present_position` prints degrees."""
    id_list = parse_ids(ids)
    values: dict[int, dict[str, object]] = {}
    units: dict[str, str] = {}
    with open_bus(require_port(port), id_list, baud, protocol) as bus:
        for motor_id in id_list:
            model = ping_model(bus, motor_id).model
            assert model is not None
            values[motor_id] = {}
            for name in registers:
                reg = model.register(name)
                units[name] = reg.unit
                values[motor_id][name] = bus.read_register(motor_id, model, name)
    if json_output:
        print_json([{"id": motor_id, **row} for motor_id, row in values.items()])
        return
    if len(id_list) == 1 and len(registers) == 1:
        console.print(fmt_value(values[id_list[0]][registers[0]], units[registers[0]]))
        return
    from rich.table import Table

    table = Table()
    table.add_column("id", justify="right")
    for name in registers:
        table.add_column(name)
    for motor_id, row in values.items():
        table.add_row(str(motor_id), *(fmt_value(row[n], units[n]) for n in registers))
    console.print(table)


@app.command("set", cls=NumbersCommand)
def set_register(
    ids: str = typer.Argument(..., help="Motor ID(s): 11, or 1-6, or 1,3,5."),
    register: str = typer.Argument(
        ..., help="Register name, e.g. goal_position.", autocompletion=complete.writable_registers
    ),
    value: str = typer.Argument(..., help="Value in SI units (degrees, deg/s, %, on/off...)."),
    port: str | None = BusPortOpt,
    baud: int | None = BaudOpt,
    protocol: int | None = ProtoOpt,
    json_output: bool = JsonOpt,
) -> None:
    """Write one register in SI units, e.g. `poppy motor set 11 goal_position -30`.

    A compliant motor (torque off) does not move to a goal: `poppy motor torque ID on` first
    (a note says so when a goal is written to one).
    """
    from poppy_core.errors import RegisterError

    id_list = parse_ids(ids)
    if register in ("id", "baudrate"):
        command = "set-id" if register == "id" else "set-baudrate"
        raise RegisterError(
            f"{register} is changed with `poppy motor {command}`, which verifies the motor "
            "still answers afterwards",
            register=register,
        )
    results: list[dict[str, object]] = []
    compliant: list[int] = []
    with open_bus(require_port(port), id_list, baud, protocol) as bus:
        for motor_id in id_list:
            model = ping_model(bus, motor_id).model
            assert model is not None
            reg = model.register(register)
            if not reg.writable:
                raise RegisterError(
                    f"{reg.name} is read-only on the {model.name}", register=reg.name
                )
            bus.write_register(motor_id, model, reg.name, parse_value(reg, value))
            written = bus.read_register(motor_id, model, reg.name)
            results.append({"id": motor_id, reg.name: written})
            if not json_output:
                console.print(f"motor {motor_id}: {reg.name} = {fmt_value(written, reg.unit)}")
            if reg.name.startswith("goal_") and not bus.read_register(
                motor_id, model, "torque_enable"
            ):
                compliant.append(motor_id)
    if json_output:
        print_json(results)
    elif compliant:
        _say_compliant(compliant, port)


def _say_compliant(ids: list[int], port: str | None) -> None:
    """A note: these motors were given a goal but are compliant, so they do not move."""
    import shlex

    from poppy_cli.output import note_line

    which = f"motor {ids[0]} is" if len(ids) == 1 else f"motors {format_ids(ids)} are"
    where = f" --port {shlex.quote(port)}" if port else ""
    them = "it" if len(ids) == 1 else "them"
    note_line(
        f"{which} compliant (torque off), so the goal moves nothing: "
        f"`poppy motor torque {format_ids(ids)} on{where}` makes {them} stiff"
    )


def _toggle(
    ids: str,
    register: str,
    state: str,
    port: str | None,
    baud: int | None,
    protocol: int | None,
    json_output: bool,
) -> None:
    set_register(ids, register, state, port, baud, protocol, json_output)


@app.command("torque")
def torque(
    ids: str = typer.Argument(..., help="Motor ID(s)."),
    state: str = typer.Argument(..., help="on or off.", autocompletion=complete.on_off),
    port: str | None = BusPortOpt,
    baud: int | None = BaudOpt,
    protocol: int | None = ProtoOpt,
    json_output: bool = JsonOpt,
) -> None:
    """Turn torque on (stiff) or off (compliant)."""
    _toggle(ids, "torque_enable", state, port, baud, protocol, json_output)


@app.command("led")
def led(
    ids: str = typer.Argument(..., help="Motor ID(s)."),
    state: str = typer.Argument(..., help="on/off, or a colour on the XL-320 (red, green, ...)."),
    port: str | None = BusPortOpt,
    baud: int | None = BaudOpt,
    protocol: int | None = ProtoOpt,
    json_output: bool = JsonOpt,
) -> None:
    """Switch the LED on or off (or pick its colour on an XL-320)."""
    _toggle(ids, "led", state, port, baud, protocol, json_output)
