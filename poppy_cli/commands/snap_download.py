"""`poppy snap download`: a pinned Snap! release fetched once into the user data folder."""

from __future__ import annotations

import sys

import typer

from poppy_cli.options import JsonSummaryOpt
from poppy_cli.output import console, print_json


def download(
    version: str | None = typer.Argument(
        None, help="The Snap! release (default: the one poppy pins, see docs/snap.md)."
    ),
    source: str | None = typer.Option(
        None,
        "--from",
        help="Where to get it: a mirror's URL, a file:// URL or a file (default: GitHub).",
    ),
    sha256: str | None = typer.Option(
        None,
        "--sha256",
        help="The release digest it must have (default: the pinned one; docs/snap.md).",
    ),
    force: bool = typer.Option(
        False, "--force", "-f", help="Download again over the installed copy."
    ),
    json_output: bool = JsonSummaryOpt,
) -> None:
    """Download Snap! once (checked, unpacked atomically): `poppy serve --snap` then serves it."""
    from poppy_core.server.snap.release import download as fetch

    shown = [0]

    def progress(size: int) -> None:
        if not json_output and size - shown[0] >= 8 << 20:
            shown[0] = size
            print(f"  {size >> 20} MiB", file=sys.stderr, flush=True)

    if not json_output:
        print("downloading Snap! (once: served offline afterwards)", file=sys.stderr, flush=True)
    copy = fetch(version, source, sha256, force=force, progress=progress)
    if json_output:
        print_json(
            {
                "version": copy.version,
                "path": str(copy.path),
                "digest": copy.digest,
                "source": copy.source,
                "archive_sha256": copy.archive_sha256 or None,
                "downloaded": copy.downloaded,
            }
        )
        return
    verb = "installed" if copy.downloaded else "already installed"
    console.print(f"Snap! {copy.version} {verb} in {copy.path}", soft_wrap=True)
    console.print("`poppy serve --snap` serves it at /app/ (offline)", soft_wrap=True)
