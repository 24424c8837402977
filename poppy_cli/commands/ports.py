"""`poppy ports`: the serial ports of this machine, their adapter, latency timer and permission."""

from __future__ import annotations

from typing import TYPE_CHECKING

from poppy_cli.options import JsonOpt
from poppy_cli.output import console, print_json, styled

if TYPE_CHECKING:
    from rich.text import Text


def ports(
    json_output: bool = JsonOpt,
) -> None:
    """List serial ports, recognise Dynamixel adapters, and say what to fix."""
    from rich.table import Table

    from poppy_core.bus.ports import list_ports

    found = list_ports()
    if json_output:
        print_json(
            [
                {
                    "device": p.device,
                    "description": p.description,
                    "usb_id": p.usb_id,
                    "serial_number": p.serial_number,
                    "adapter": p.adapter,
                    "latency_timer_ms": p.latency_timer_ms,
                    "accessible": p.accessible,
                    "advice": p.advice,
                }
                for p in found
            ]
        )
        return
    if not found:
        console.print(
            "No serial port found. Plug the USB2AX/U2D2 adapter in, "
            "or start a virtual bus with poppy emulate."
        )
        return
    table = Table(title="Serial ports")
    for column in ("port", "adapter", "USB id", "latency", "access", "description"):
        table.add_column(column)
    for p in found:
        latency: str | Text = "-" if p.latency_timer_ms is None else f"{p.latency_timer_ms} ms"
        if p.latency_timer_ms is not None and p.latency_timer_ms > 1:
            latency = styled("[yellow]{}[/]", latency)
        access = styled("[green]ok[/]") if p.accessible else styled("[red]denied[/]")
        table.add_row(p.device, p.adapter or "-", p.usb_id or "-", latency, access, p.description)
    console.print(table)
    for p in found:
        for hint in p.advice:
            console.print(styled("[yellow]{}[/]: {}", p.device, hint))
