"""`poppy notebook`: a Jupyter server whose notebooks reach the served robot (`from_remote()`).

The robot's URL reaches the kernels through ``POPPY_ROBOT_URL`` (Jupyter's kernels inherit its
environment), so a notebook's first cell is ``robot = from_remote()``. The shipped notebooks
(``poppy_cli/notebooks/``) are copied into the notebook folder when absent, never over a file
there (the user's edits are theirs).
"""

from __future__ import annotations

import os
import sys
from collections.abc import Sequence
from importlib.resources import files
from pathlib import Path
from typing import NoReturn
from urllib.parse import urlsplit

import typer

from poppy_cli.output import EXIT_USAGE, error_line

DEFAULT_ROBOT = "http://127.0.0.1:8080"
DEFAULT_PORT = 8888
FIRST_NOTEBOOK = "discover-your-robot.ipynb"


def notebooks_folder() -> Path:
    """The default notebook folder: ``<user data>/poppy/notebooks``."""
    import platformdirs

    return Path(platformdirs.user_data_dir("poppy")) / "notebooks"


def shipped_notebooks() -> dict[str, bytes]:
    """The notebooks poppy ships: file name -> content."""
    folder = files("poppy_cli") / "notebooks"
    return {
        entry.name: entry.read_bytes()
        for entry in folder.iterdir()
        if entry.name.endswith(".ipynb")
    }


def add_shipped_notebooks(folder: Path) -> list[Path]:
    """Copy the shipped notebooks missing from ``folder`` (created if needed); the ones added."""
    from poppy_core.errors import FileError
    from poppy_core.files import write_file

    added = []
    for name, data in sorted(shipped_notebooks().items()):
        target = folder / name
        if target.exists() or target.is_symlink():
            continue
        try:
            added.append(write_file(target, data, make_folder=True))
        except FileError:
            if not target.exists():  # not a race with another copy: say it
                raise
    return added


def check_robot_url(url: str) -> str:
    """``url`` as an ``http(s)://host[:port]`` base, or a usage error."""
    parts = urlsplit(url.strip())
    try:
        port_ok = parts.port is None or 0 < parts.port < 65536
    except ValueError:
        port_ok = False
    if parts.scheme not in ("http", "https") or not parts.hostname or not port_ok:
        _usage(
            f"--robot {url[:80]!r} is not a robot's URL: give http://HOST:PORT of "
            "`poppy serve --http`, e.g. http://poppy.local:8080"
        )
    if parts.path.strip("/") or parts.query or parts.fragment:
        _usage(f"--robot {url[:80]!r}: give the server's base URL, without a path")
    return f"{parts.scheme}://{parts.netloc}"


def jupyter_command(
    host: str, port: int, folder: Path, open_browser: bool, as_root: bool = False
) -> list[str]:
    """The Jupyter Notebook server's command line (``python -m notebook``); ``as_root`` passes
    ``--allow-root``, without which Jupyter refuses to start as root."""
    args = [sys.executable, "-m", "notebook", f"--ServerApp.ip={host}"]
    args += [f"--ServerApp.port={port}", "--ServerApp.port_retries=0"]
    args += [f"--ServerApp.root_dir={folder}"]
    if not open_browser:
        args.append("--no-browser")
    if as_root:
        args.append("--allow-root")
    return args


def running_as_root() -> bool:
    """Whether this process runs as root (the default user of many Pi images and containers)."""
    return hasattr(os, "geteuid") and os.geteuid() == 0


def run_jupyter(args: Sequence[str], env: dict[str, str]) -> NoReturn:
    """Become the Jupyter server (its signals, exit code and logs are the service's)."""
    sys.stdout.flush()
    sys.stderr.flush()
    os.execve(args[0], list(args), env)


def notebook(
    robot: str = typer.Option(
        DEFAULT_ROBOT,
        "--robot",
        help="The served robot the notebooks reach (`poppy serve --http`).",
    ),
    host: str = typer.Option("127.0.0.1", "--host", help="Address Jupyter listens on."),
    port: int = typer.Option(
        DEFAULT_PORT, "--port", "-p", min=1, max=65535, help="Jupyter's TCP port."
    ),
    folder: Path | None = typer.Option(
        None,
        "--dir",
        help="Folder of the notebooks (default: the user data folder's poppy/notebooks).",
    ),
    no_browser: bool = typer.Option(False, "--no-browser", help="Do not open a web browser."),
) -> None:
    """Start Jupyter with the "Discover your robot" notebook; `robot = from_remote()` reaches
    the robot at --robot."""
    from poppy_core.extras import require

    base = check_robot_url(robot)
    require("jupyter_server", "notebook", "ipykernel", extra="notebook")
    where = (folder or notebooks_folder()).expanduser()
    if where.exists() and not where.is_dir():
        _usage(f"--dir {where}: not a folder")
    for added in add_shipped_notebooks(where):
        print(f"added {added}", file=sys.stderr, flush=True)
    env = dict(os.environ, POPPY_ROBOT_URL=base)
    as_root = running_as_root()
    if as_root:
        print(
            "warning: running as root, so Jupyter is started with --allow-root "
            "(its notebooks can change anything on this machine; a user account is safer)",
            file=sys.stderr,
            flush=True,
        )
    shown = f"[{host}]" if ":" in host else host
    print(
        f"Jupyter on http://{shown}:{port}/notebooks/{FIRST_NOTEBOOK} (notebooks in {where}); "
        f"the robot: {base}",
        file=sys.stderr,
        flush=True,
    )
    run_jupyter(jupyter_command(host, port, where, not no_browser, as_root), env)


def _usage(message: str) -> NoReturn:
    error_line(message)
    raise typer.Exit(EXIT_USAGE)
