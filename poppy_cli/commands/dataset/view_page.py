"""`poppy dataset view REPO_ID` without an export: the robot's page serves the dataset on
loopback, a simulated robot of its robot_type behind it (for the 3D view's model; the episode
poses the view, never a motor); prints the page's URL and serves until Ctrl-C or SIGTERM."""

from __future__ import annotations

import json
import signal
import sys
import threading
from pathlib import Path

import typer

from poppy_cli.commands.dataset.checks import usage
from poppy_cli.output import EXIT_FAILURE, error_line, warn_line
from poppy_cli.robots import build_robot

HOST = "127.0.0.1"


def serve_page(
    repo_id: str,
    folder: Path,
    episode: int | None,
    profile: str | None,
    http_port: int,
    open_browser: bool,
    json_output: bool,
) -> None:
    """Serve the page with the dataset in ``folder`` listed as ``repo_id``; the URL opens
    ``episode`` (when given) in the player."""
    from poppy_core.assembly import Listen, ServeSpec, serve
    from poppy_core.dataset.reader import read_summary
    from poppy_core.errors import PoppyError
    from poppy_core.server.web.datasets import add_dataset

    try:
        summary = read_summary(folder)
    except PoppyError as exc:
        raise usage(str(exc), "--root") from None
    indices = [e.index for e in summary.episodes]
    if episode is not None and episode not in indices:
        there = f"{indices[0]} to {indices[-1]}" if indices else "none"
        raise usage(f"no episode {episode} in this dataset (episodes: {there})", "--episode")
    model = profile or _profile_of(summary.robot_type)
    spec = ServeSpec(http=Listen(HOST, http_port), warn=warn_line)
    stop = threading.Event()
    previous = signal.signal(signal.SIGTERM, lambda signum, frame: stop.set())
    try:
        with build_robot(model, None, None, True) as robot:
            servers = serve(robot, spec, start=False)
            try:
                add_dataset(servers.app, repo_id, folder)
                servers.start()
                assert servers.http is not None
                chosen = episode if episode is not None else (indices[0] if indices else 0)
                url = f"http://{HOST}:{servers.http.port}/#dataset={repo_id}&episode={chosen}"
                _announce(url, repo_id, folder, chosen, model, len(indices), json_output)
                if open_browser:
                    import webbrowser

                    if not webbrowser.open(url):
                        warn_line("could not open a browser: open the URL above yourself")
                while not stop.wait(0.2):
                    if not servers.http.running:
                        break
            except KeyboardInterrupt:
                pass
            except RuntimeError as exc:
                error_line(f"{exc} (the server's log above says why)")
                raise typer.Exit(EXIT_FAILURE) from None
            finally:
                servers.stop()
    finally:
        signal.signal(signal.SIGTERM, previous)
    print("stopped", file=sys.stderr, flush=True)


def _profile_of(robot_type: str | None) -> str:
    """The profile named by the dataset's robot_type; none: a usage error asking --profile."""
    from poppy_core.errors import ConfigError
    from poppy_core.robot.profiles import load_profile

    if robot_type:
        try:
            load_profile(robot_type)
            return robot_type
        except ConfigError:
            pass
    raise usage(
        f"the dataset's robot_type {robot_type or '(none)'} is no profile here: give --profile "
        "(the robot drawn in the 3D view)",
        "--profile",
    )


def _announce(
    url: str,
    repo_id: str,
    folder: Path,
    episode: int,
    profile: str,
    episodes: int,
    json_output: bool,
) -> None:
    if json_output:
        summary = {
            "url": url,
            "repo_id": repo_id,
            "root": str(folder),
            "episode": episode,
            "episodes": episodes,
            "profile": profile,
        }
        print(json.dumps(summary), flush=True)
        return
    print(f"page: {url}", flush=True)
    print(
        f"{repo_id}: {episodes} episode(s) on a simulated {profile} (the robot is not moved); "
        "Ctrl-C stops",
        file=sys.stderr,
        flush=True,
    )
