"""`poppy fleet`: many robots at once. This group only registers its commands, each in its own
module: list, status, run, play and stop over Zenoh (`fleet_zenoh`)."""

from __future__ import annotations

import typer

from poppy_cli.commands import fleet_zenoh

app = typer.Typer(help="Many robots at once: list, watch and drive a fleet.", no_args_is_help=True)
fleet_zenoh.register(app)
