"""Which serial port(s) `poppy scan` looks at when no --port is given, and why, said aloud."""

from __future__ import annotations

from typing import TYPE_CHECKING

import typer

from poppy_cli.output import EXIT_FAILURE, EXIT_USAGE, counted, error_line, note_line
from poppy_cli.prompts import ask

if TYPE_CHECKING:
    from poppy_core.bus.ports import PortInfo


def _label(info: PortInfo) -> str:
    """``/dev/ttyUSB0 (U2D2, 0403:6014)`` or ``/dev/ttyS0 (ttyS0)``."""
    what = [info.adapter or info.description or "unknown", info.usb_id or ""]
    return f"{info.device} ({', '.join(w for w in what if w)})"


def choose_ports(ports: list[PortInfo]) -> list[str]:
    """The ports to scan among ``ports`` (none given on the command line), with a note saying
    which and why: the recognised Dynamixel adapters (USB2AX, U2D2, FTDI by USB VID:PID), else
    the only port there is; several unrecognised ports are a question on a terminal, else a
    usage error that lists them."""
    if not ports:
        error_line("no serial port found: plug the adapter in (see `poppy ports`) or give --port")
        raise typer.Exit(EXIT_FAILURE)
    adapters = [p for p in ports if p.adapter is not None]
    if adapters:
        others = len(ports) - len(adapters)
        skipped = f"; {counted(others, 'other port')} skipped, see `poppy ports`" if others else ""
        what = "a recognised Dynamixel adapter" if len(adapters) == 1 else "recognised adapters"
        note_line(
            "scanning "
            + ", ".join(_label(p) for p in adapters)
            + f": {what}{skipped}; give --port to scan another"
        )
        return [p.device for p in adapters]
    if len(ports) == 1:
        note_line(
            f"scanning {_label(ports[0])}, the only serial port (not a recognised Dynamixel "
            "adapter: USB2AX, U2D2 or FTDI); give --port to scan another"
        )
        return [ports[0].device]
    listed = ", ".join(_label(p) for p in ports)
    question = (
        f"no recognised Dynamixel adapter; serial ports: {listed}. Which one to scan "
        f"(1-{len(ports)}, or a path)?"
    )
    for _ in range(3):
        answer = ask(question)
        if answer is None:  # not a terminal: nothing asked
            error_line(
                f"no recognised Dynamixel adapter among {len(ports)} serial ports ({listed}): "
                "give one with --port"
            )
            raise typer.Exit(EXIT_USAGE)
        picked = answer.strip()
        if picked.isdigit() and 1 <= int(picked) <= len(ports):
            return [ports[int(picked) - 1].device]
        if picked in (p.device for p in ports):
            return [picked]
    error_line("no port chosen: give one with --port")
    raise typer.Exit(EXIT_USAGE)
