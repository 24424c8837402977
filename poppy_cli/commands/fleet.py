"""`poppy fleet`: many robots at once. This group only registers its commands, each in its own
module: discover (mDNS, `fleet_discover`); list, status, run, play and stop over Zenoh
(`fleet_zenoh`); router, a Zenoh router for them (`fleet_router`); serve, the teacher's page
(`fleet_serve`)."""

from __future__ import annotations

import typer

from poppy_cli.commands import fleet_discover, fleet_router, fleet_serve, fleet_zenoh

app = typer.Typer(
    help="Many robots at once: find the ones announced, list, watch and drive a fleet.",
    no_args_is_help=True,
)
app.command("discover")(fleet_discover.discover)
app.command("router")(fleet_router.router)
fleet_zenoh.register(app)
app.command("serve")(fleet_serve.fleet_serve)
