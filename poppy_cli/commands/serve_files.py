"""`poppy serve --settings FILE --token-file FILE`: the appliance's options and token read from
the files `poppy service install` writes and the page's settings change."""

from __future__ import annotations

from pathlib import Path
from typing import NoReturn

import typer

from poppy_cli.output import EXIT_FAILURE, EXIT_USAGE, error_line


def _fail(message: str, code: int) -> NoReturn:
    error_line(message)
    raise typer.Exit(code)


def read_served_files(
    settings: Path | None,
    token_file: Path | None,
    token: str | None,
    snap: bool,
    zmq: bool,
) -> tuple[bool, bool, str | None]:
    """``(snap, zmq, token)`` with the files' values; a conflict or a bad file is one line."""
    from poppy_core.errors import ConfigError, FileError
    from poppy_core.server.serve_options import read_options, read_token

    if settings is not None and (snap or zmq):
        _fail(
            "--settings decides Snap! and ZMQ (the page switches them there): leave --snap "
            "and --zmq out",
            EXIT_USAGE,
        )
    if token_file is not None and token:
        _fail("give --token (or POPPY_TOKEN) or --token-file, not both", EXIT_USAGE)
    try:
        if settings is not None:
            options = read_options(settings)
            snap, zmq = options.snap, options.zmq
        if token_file is not None:
            token = read_token(token_file)
    except (ConfigError, FileError) as exc:
        _fail(str(exc), EXIT_FAILURE)
    return snap, zmq, token
