"""`poppy dataset delete-episode`: remove an episode; the later ones move one number down."""

from __future__ import annotations

from pathlib import Path

import typer

from poppy_cli.commands.dataset.checks import EpisodeOpt, RootOpt, core, dataset_folder
from poppy_cli.options import JsonSummaryOpt
from poppy_cli.output import console, print_json


def delete_episode(
    repo_id: str = typer.Argument(..., help="The dataset's name, user/name."),
    episode: int = EpisodeOpt,
    root: Path | None = RootOpt,
    json_output: bool = JsonSummaryOpt,
) -> None:
    """Remove an episode; the later ones move one number down (indices, tasks, stats, videos).

    The new dataset is built beside the old one and swapped in at once: an interrupted
    deletion leaves the dataset as it was.
    """
    from poppy_core.dataset.delete import delete_episode as delete

    folder = dataset_folder(repo_id, root)
    done = core(lambda: delete(folder, episode), "--episode")
    if json_output:
        print_json(
            {
                "root": str(folder),
                "deleted": done.episode,
                "frames": done.frames,
                "total_episodes": done.episodes_left,
                "total_frames": done.frames_left,
                "total_tasks": done.tasks_left,
            }
        )
        return
    console.print(
        f"deleted episode {done.episode} ({done.frames} frames); {done.episodes_left} episodes, "
        f"{done.frames_left} frames left",
        highlight=False,
    )
