"""`poppy dataset info|list`: what a dataset holds, and its episodes."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import typer

from poppy_cli.options import JsonOpt
from poppy_cli.output import console, print_json, printable


def info(
    root: Path = typer.Argument(..., help="The dataset's folder."),
    json_output: bool = JsonOpt,
) -> None:
    """What a dataset holds: episodes, frames, duration, tasks, cameras, joints."""
    summary = _summary(root)
    if json_output:
        print_json(summary.as_json())
        return
    console.print(
        f"{printable(str(summary.root))}: LeRobot {summary.codebase_version}, "
        f"{len(summary.episodes)} episodes, {summary.frames} frames, "
        f"{summary.duration_s:.1f} s at {summary.fps} fps",
        highlight=False,
    )
    console.print(
        f"robot: {summary.robot_type or '-'}; joints: {', '.join(summary.joints)}", highlight=False
    )
    console.print(f"cameras: {', '.join(summary.cameras) or 'none'}", highlight=False)
    for index, text in enumerate(summary.tasks):
        console.print(f"task {index}: {printable(text)}", highlight=False)


def list_episodes(
    root: Path = typer.Argument(..., help="The dataset's folder."),
    json_output: bool = JsonOpt,
) -> None:
    """The episodes of a dataset: frames, duration, task."""
    summary = _summary(root)
    rows = [
        {
            "episode": e.index,
            "frames": e.frames,
            "duration_s": round(e.duration_s, 3),
            "tasks": list(e.tasks),
        }
        for e in summary.episodes
    ]
    if json_output:
        print_json(rows)
        return
    from rich.table import Table

    table = Table(title=f"{len(rows)} episodes at {summary.fps} fps")
    for column in ("episode", "frames", "duration", "task"):
        table.add_column(column, justify="left" if column == "task" else "right")
    for row in rows:
        table.add_row(
            str(row["episode"]),
            str(row["frames"]),
            f"{row['duration_s']:.2f} s",
            printable(", ".join(row["tasks"])),
        )
    console.print(table)


def _summary(root: Path) -> Any:
    from poppy_core.extras import require

    require("pyarrow", extra="dataset")
    from poppy_core.dataset.reader import read_summary

    return read_summary(root)
