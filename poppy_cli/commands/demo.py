"""`poppy demo`: a virtual Ergo Jr in-process, found by a scan and read in SI units."""

from __future__ import annotations

import typer

from poppy_cli.output import console, fmt_value


def demo(
    wire_timing: bool = typer.Option(
        True, "--wire-timing/--no-wire-timing", help="Emulate the wire's timing (1 Mbps)."
    ),
) -> None:
    """Start a virtual Ergo Jr (six XL-320), scan its bus, and show what was found."""
    from rich.table import Table

    from poppy_cli.commands.scan import render_found
    from poppy_core.bus import scan as run_scan
    from poppy_core.bus.dxlbus import DxlBus
    from poppy_core.emulator import ergo_jr_bus, serve_pty
    from poppy_core.models import ServoModel

    virtual = ergo_jr_bus(wire_timing=wire_timing, latency_s=0.001 if wire_timing else 0.0)
    with serve_pty(virtual) as server:
        console.print(
            f"[bold]Virtual Poppy Ergo Jr[/]: 6 XL-320 on {server.url} (protocol 2, 1 Mbps)"
        )
        with console.status("scanning IDs 0-253 at 1 Mbps, protocol 2…"):
            found = run_scan(server.url, [1_000_000], [2])
        render_found(found)
        table = Table(title="state of the motors found")
        for column in ("id", "position", "temperature", "voltage", "torque", "led"):
            table.add_column(column, justify="right")
        with DxlBus(server.url, 1_000_000, 2) as bus:
            for motor in found:
                result = bus.ping(motor.id)
                assert result is not None and result.model is not None
                model = result.model

                def get(name: str, motor_id: int = motor.id, model: ServoModel = model) -> str:
                    reg = model.register(name)
                    return fmt_value(bus.read_register(motor_id, model, name), reg.unit)

                table.add_row(
                    str(motor.id),
                    get("present_position"),
                    get("present_temperature"),
                    get("present_voltage"),
                    get("torque_enable"),
                    get("led"),
                )
        console.print(table)
        console.print(
            "Next: [bold]poppy emulate --profile ergo-jr[/] serves this robot to other programs; "
            "[bold]poppy scan --port PATH[/] finds its motors."
        )
