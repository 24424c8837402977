"""`poppy dataset record|info|list|replay|view|delete-episode`: LeRobot datasets (v3.0).

The format is ``poppy_core.dataset``; the recording loop ``poppy_core.motion.episodes``. One
module a subcommand (``record``, ``look`` for info and list, ``replay``, ``view`` for the
exports, ``delete``); the recording's parts beside it: ``checks`` (the options' refusals),
``sources`` (the source of actions), ``recording`` (robot, cameras, writer, the episodes'
loop) and ``live`` (the keys and the live line).
"""

from __future__ import annotations

import typer

from poppy_cli.commands.dataset import delete, look, record, replay, view

app = typer.Typer(
    help="LeRobot datasets (v3.0): record episodes from a robot, look at them.",
    no_args_is_help=True,
)
app.command("record")(record.record)
app.command("info")(look.info)
app.command("list")(look.list_episodes)
app.command("replay")(replay.replay)
app.command("delete-episode")(delete.delete_episode)
app.command("view")(view.view)
