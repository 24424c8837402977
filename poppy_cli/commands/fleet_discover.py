"""`poppy fleet discover`: the robots announced on the network (`poppy serve --announce`)."""

from __future__ import annotations

import typer

from poppy_cli.options import JsonOpt, finite
from poppy_cli.output import console, print_json, styled


def discover(
    timeout: float = typer.Option(
        3.0,
        "--timeout",
        min=0.1,
        max=120.0,
        callback=finite,
        help="Seconds to listen for announcements (at least 2 to hear every robot).",
    ),
    interface: list[str] | None = typer.Option(
        None,
        "--interface",
        help="Listen on the interface of this IPv4 address only (repeat it); default: every one.",
    ),
    json_output: bool = JsonOpt,
) -> None:
    """List the robots announced over mDNS: name, creature, version and URLs."""
    from rich.table import Table

    from poppy_core.remote.discovery import discover as find

    robots = find(timeout, interfaces=interface or None)
    if json_output:
        print_json([r.as_dict() for r in robots])
        return
    if not robots:
        console.print(
            f"No robot announced itself within {timeout:g} s. A robot announces itself when "
            "served with `poppy serve --announce` (the installed service does)."
        )
        return
    table = Table(title="Robots on the network")
    for column in ("name", "creature", "version", "addresses", "URLs"):
        table.add_column(column)
    for r in robots:
        urls = "\n".join(f"{p}: {u}" for p, u in r.urls.items())
        table.add_row(r.name, r.creature or "-", r.version or "-", ", ".join(r.addresses), urls)
    console.print(table)
    if any(r.token for r in robots):
        console.print(styled("[yellow]{}[/]", "some robots ask for a token (their owner has it)"))
