"""`poppy fleet`: the robots on the network (this module only registers the commands)."""

from __future__ import annotations

import typer

from poppy_cli.commands import fleet_discover

app = typer.Typer(help="Robots on the network: find the ones announced.", no_args_is_help=True)

app.command("discover")(fleet_discover.discover)
