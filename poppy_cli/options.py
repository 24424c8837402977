"""Options shared by commands (robot, bus, output) and their parsers: IDs, baud rates, protocols."""

from __future__ import annotations

import math
import os

import typer


def parse_ids(text: str) -> list[int]:
    """Parse "0-253", "1,2,5-7" into a sorted list of IDs in 0..253."""
    ids: set[int] = set()
    for part in text.replace(" ", "").split(","):
        if not part:
            continue
        try:
            if "-" in part:
                lo_text, hi_text = part.split("-", 1)
                lo, hi = int(lo_text), int(hi_text)
                if lo > hi:
                    raise typer.BadParameter(
                        f"range {part!r} goes backwards; write it as {hi}-{lo}"
                    )
                ids.update(range(lo, hi + 1))
            else:
                ids.add(int(part))
        except ValueError:
            raise typer.BadParameter(
                f"{part!r} is not an ID or a range; use e.g. 1-6 or 1,3,11-15"
            ) from None
    bad = sorted(i for i in ids if not 0 <= i <= 253)
    if bad:
        raise typer.BadParameter(f"ID {bad[0]} is out of range; Dynamixel IDs are 0-253")
    if not ids:
        raise typer.BadParameter("no ID given; use e.g. 0-253 or 1,2,3")
    return sorted(ids)


def parse_protocols(text: str) -> list[int]:
    """Parse "1", "2" or "both"."""
    value = text.strip().lower()
    if value == "both":
        return [1, 2]
    if value in ("1", "2", "1.0", "2.0"):
        return [int(float(value))]
    raise typer.BadParameter(f"protocol {text!r} is not 1, 2 or both")


def default_port(port: str | None) -> str | None:
    """The port given, or POPPY_PORT from the environment."""
    return port or os.environ.get("POPPY_PORT") or None


# Dynamixel rates run from 9,600 bps (the slowest code of AX/MX/X) to 10.5 Mbps (X-series); the
# range is left a little wider for adapters, and refuses 0 or a rate no UART takes.
MIN_BAUD = 1_200
MAX_BAUD = 12_000_000
BAUD_LIMITS = {"min": MIN_BAUD, "max": MAX_BAUD}
"""Kept for callers; write ``typer.Option(..., min=MIN_BAUD, max=MAX_BAUD)`` (typed): a rate
out of range is a usage error (exit 2)."""


MAX_DURATION_S = 86_400.0
"""A day: the longest goto or move core accepts (``poppy_core.trajectory`` and
``poppy_core.motion.move``); longer is a typing mistake that would never end."""


def finite(value: float | None) -> float | None:
    """An option callback: NaN and infinities are usage errors (a range check lets NaN by)."""
    if value is not None and not math.isfinite(value):
        raise typer.BadParameter(f"{value} is not a finite number")
    return value


PORT_HELP = (
    "Serial port: a device (/dev/ttyUSB0), a pty, or a URL (socket://127.0.0.1:4000)."
    " [env: POPPY_PORT]"
)
BAUD_HELP = "Baud rate in bps (default: search the standard rates)."
PROTOCOL_HELP = "Dynamixel protocol: 1 or 2 (default: search both)."


# -- the robot options of every command that builds one ----------------------------------------

ProfileOpt = typer.Option(
    None, "--profile", help="Robot profile, e.g. ergo-jr. [env: POPPY_PROFILE, or user settings]"
)
ConfigOpt = typer.Option(None, "--config", "-c", help="Robot config file (JSON or YAML).")
PortOpt = typer.Option(
    None, "--port", "-p", help="Serial port of the robot's bus. [env: POPPY_PORT]"
)


def _sim_engine(value: str | None) -> str | None:
    """Check the engine of ``--sim`` (the root group turns a bare ``--sim`` into ``ideal``)."""
    if value is not None and value not in ("ideal", "mujoco"):
        raise typer.BadParameter(f"{value!r}: use --sim (ideal servos) or --sim mujoco (physics)")
    return value


SimOpt = typer.Option(
    None,
    "--sim",
    metavar="[mujoco]",
    callback=_sim_engine,
    help="Build a virtual robot: --sim (ideal servos) or --sim mujoco (MuJoCo physics).",
)
JsonOpt = typer.Option(False, "--json", help="Print JSON instead of a table.")
RemoteOpt = typer.Option(
    None,
    "--remote",
    help="Drive a robot served by `poppy serve --http` at this URL (token: env POPPY_TOKEN).",
)
