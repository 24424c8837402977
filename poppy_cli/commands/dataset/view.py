"""`poppy dataset view`: the robot's page playing the dataset's episodes (``view_page``), or
an episode exported for a viewer (Foxglove's MCAP, Rerun's .rrd).

The refusals (no dataset, no such episode, no export asked, a file there without --force, an
extra not installed) come before anything is written; each file is put in place whole.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import typer

from poppy_cli.commands.dataset.checks import RootOpt, core, dataset_folder, usage
from poppy_cli.options import JsonSummaryOpt, profile_option
from poppy_cli.output import console, print_json, printable, warn_line


def view(
    repo_id: str = typer.Argument(..., help="The dataset's name, user/name."),
    root: Path | None = RootOpt,
    episode: int | None = typer.Option(
        None,
        "--episode",
        min=0,
        help="The episode's number (from 0): the one exported (needed with --mcap or --rerun), "
        "or the one the page opens.",
    ),
    mcap: Path | None = typer.Option(
        None, "--mcap", help="Write the episode to this MCAP file (Foxglove: Open local file)."
    ),
    rerun: Path | None = typer.Option(
        None, "--rerun", help="Write the episode to this Rerun file (.rrd: rerun FILE)."
    ),
    force: bool = typer.Option(False, "--force", "-f", help="Replace an existing file."),
    profile: str | None = profile_option(
        "The robot's model (URDF, joint frames). [default: the dataset's robot_type]"
    ),
    http_port: int = typer.Option(
        0, "--http-port", min=0, max=65535, help="The page's port on 127.0.0.1 (0: a free one)."
    ),
    open_browser: bool = typer.Option(False, "--open", help="Open the page in the browser."),
    json_output: bool = JsonSummaryOpt,
) -> None:
    """Play the episodes on the robot's page (served on 127.0.0.1, a simulated robot of the
    dataset's robot_type behind it: the 3D view, the camera videos, state against action per
    joint; prints its URL, Ctrl-C stops), or export an episode stamped with the dataset's frame
    timestamps: --mcap FILE for Foxglove (state, action, camera, the robot's 3D model, the task),
    --rerun FILE.rrd for Rerun (state and action per motor, camera, task)."""
    if mcap is None and rerun is None:
        if force:
            raise usage("--force replaces an exported file: give --mcap or --rerun", "--force")
        from poppy_cli.commands.dataset.view_page import serve_page

        folder = dataset_folder(repo_id, root)
        serve_page(repo_id, folder, episode, profile, http_port, open_browser, json_output)
        return
    if episode is None:
        raise usage("give --episode K: the episode to export", "--episode")
    if open_browser:
        raise usage("--open opens the page: leave out --mcap and --rerun", "--open")
    if mcap is not None and rerun is not None and mcap.expanduser() == rerun.expanduser():
        raise usage("--mcap and --rerun name the same file: give two files", "--rerun")
    from poppy_core.extras import require
    from poppy_core.files import output_path

    if mcap is not None:
        require("foxglove", extra="foxglove")
    if rerun is not None:
        require("rerun", extra="rerun")
    folder = dataset_folder(repo_id, root)
    from poppy_core.dataset.episode import read_episode

    index: int = episode
    chosen = core(lambda: read_episode(folder, index), "--episode")
    for path in (mcap, rerun):
        if path is not None:
            output_path(path, replace=force)
    summary: dict[str, Any] = {"root": str(folder), "episode": episode, "frames": len(chosen)}
    lines = []
    if mcap is not None:
        from poppy_core.server.foxglove.dataset_file import write_episode_mcap

        config = _robot_model(profile, chosen.robot_type)
        written = write_episode_mcap(chosen, mcap, config, replace=force)
        summary.update(mcap=str(written.path), messages=written.messages)
        lines.append(f"MCAP for Foxglove: {printable(str(written.path))}")
    if rerun is not None:
        from poppy_core.dataset.rerun_file import write_episode_rrd

        recording = write_episode_rrd(
            chosen, rerun, name=f"{repo_id} episode {episode}", replace=force
        )
        summary.update(rerun=str(recording.path), rows=recording.rows)
        lines.append(f"Rerun recording: {printable(str(recording.path))}")
    if json_output:
        print_json(summary)
        return
    console.print(
        f"episode {episode} ({len(chosen)} frames) of {printable(str(folder))}: "
        + "; ".join(lines),
        soft_wrap=True,
        highlight=False,
        markup=False,
    )


def _robot_model(profile: str | None, robot_type: str | None) -> Any:
    """The config of ``profile`` (an unknown one: exit 1 with a suggestion), else of the
    dataset's robot_type when it names a profile here, else None (said once)."""
    from poppy_core.errors import ConfigError
    from poppy_core.robot.profiles import load_profile

    if profile is not None:
        return load_profile(profile)
    if robot_type:
        try:
            return load_profile(robot_type)
        except ConfigError:
            pass
    warn_line(
        f"no robot model: the dataset's robot_type {robot_type or '(none)'} is no profile here; "
        "joint angles are written without the URDF (give --profile)"
    )
    return None
