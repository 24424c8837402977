"""The Snap! part of `poppy serve --snap`: options checked, URLs printed.

``poppy_core.assembly.serve`` builds the server, with the others.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, NoReturn

import typer

from poppy_cli.output import EXIT_USAGE, error_line, warn_line

if TYPE_CHECKING:
    from poppy_core.server.snap import SnapServer


def _usage(message: str) -> NoReturn:
    error_line(message)
    raise typer.Exit(EXIT_USAGE)


def check_snap_options(snap: bool, snap_dir: Path | None, open_browser: bool) -> Path | None:
    """Refuse Snap! options that cannot work, before the robot is built; the Snap! copy to serve
    at /app/ (``--snap-dir``, else the one ``poppy snap download`` installed, else None). Its
    port is checked with the others by ``ServeSpec``."""
    if not snap:
        for given, name in ((snap_dir is not None, "--snap-dir"), (open_browser, "--open")):
            if given:
                _usage(f"{name} needs --snap (it concerns the Snap! server)")
        return None
    if snap_dir is not None and not (snap_dir / "snap.html").is_file():
        _usage(
            f"--snap-dir {snap_dir}: no snap.html there; give the folder of a downloaded Snap! "
            "(`poppy snap download` installs one)"
        )
    if snap_dir is not None:
        return snap_dir
    from poppy_core.server.snap.release import installed

    copy = installed()
    return copy.path if copy is not None else None


def announce_snap(server: SnapServer, open_browser: bool) -> None:
    """Print the Snap! server's URLs; open Snap! with the Poppy blocks when asked."""
    print(f"snap: {server.url}", flush=True)
    if not server.local_app:
        warn_line(
            "no Snap! downloaded: the link opens snap.berkeley.edu (online); "
            "`poppy snap download` once gets a copy served offline at /app/"
        )
    print(f"Snap! with the Poppy blocks: {server.editor_url}", flush=True)
    if open_browser:
        import webbrowser

        if not webbrowser.open(server.editor_url):
            warn_line("could not open a browser: open the Snap! URL above yourself")
