"""Shared console helpers: Rich on stdout, errors on stderr, JSON for scripts."""

from __future__ import annotations

import json
import sys
from typing import Any

from rich.console import Console

EXIT_OK = 0
EXIT_FAILURE = 1
EXIT_USAGE = 2
EXIT_INTERRUPTED = 130

console = Console(highlight=False)
err_console = Console(stderr=True, highlight=False)


def print_json(data: Any) -> None:
    """Write `data` as JSON on stdout, nothing else."""
    sys.stdout.write(json.dumps(data, indent=2, default=str) + "\n")
    sys.stdout.flush()


def error_line(message: str) -> None:
    """Print one clear error line on stderr."""
    err_console.print(f"[bold red]error:[/] {message}", soft_wrap=True)


def warn_line(message: str) -> None:
    """Print one warning line on stderr."""
    err_console.print(f"[yellow]warning:[/] {message}", soft_wrap=True)


def fmt_value(value: Any, unit: str = "") -> str:
    """Format an SI register value with its unit for humans."""
    if isinstance(value, bool):
        return "on" if value else "off"
    if isinstance(value, float):
        text = f"{value:.2f}".rstrip("0").rstrip(".") if abs(value) < 1e6 else f"{value:.0f}"
        if text == "-0":
            text = "0"
    else:
        text = str(value)
    return f"{text} {unit}".strip() if unit else text
