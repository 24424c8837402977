"""The files of `poppy service install` beside its units: the serve options file (Snap!, ZMQ)
and the token file that `poppy.service` reads (`poppy serve --settings F --token-file F`), in
the service user's config folder, owned by that user (the page's settings rewrite them)."""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

from poppy_core.server.serve_options import (
    OPTIONS_NAME,
    SERVICE_DIR_ENV,
    TOKEN_NAME,
    ServeOptions,
    new_token,
    read_token,
    service_folder,
    write_options,
    write_token,
)


@dataclass(frozen=True)
class ServiceFiles:
    """Where the service's files are."""

    folder: Path

    @property
    def settings(self) -> Path:
        """The serve options file."""
        return self.folder / OPTIONS_NAME

    @property
    def token(self) -> Path:
        """The token file (mode 600)."""
        return self.folder / TOKEN_NAME


def files_of(run_as: str | None) -> ServiceFiles:
    """The service's files: ``POPPY_SERVICE_DIR``; for a system service, the config folder of
    the user it runs as (``~USER/.config/poppy/service``); else the current user's."""
    if run_as is None or os.environ.get(SERVICE_DIR_ENV):
        return ServiceFiles(service_folder())
    import pwd

    home = Path(pwd.getpwnam(run_as).pw_dir)
    return ServiceFiles(home / ".config" / "poppy" / "service")


def write_files(
    files: ServiceFiles, options: ServeOptions, token: bool, owner: str | None
) -> str | None:
    """Write the options file and, with ``token``, a token file when there is no valid one
    (a reinstall keeps the token the page set); returns the new token, or None. The files and
    their folder are given to ``owner`` when root writes them."""
    from poppy_core.errors import ConfigError, FileError
    from poppy_core.files import file_error

    folder = files.folder
    created = [p for p in (folder.parent.parent, folder.parent, folder) if not p.exists()]
    try:
        folder.mkdir(mode=0o700, parents=True, exist_ok=True)
    except OSError as exc:
        raise file_error(exc, folder, "create") from None
    write_options(files.settings, options)
    made = None
    if token:
        try:
            read_token(files.token)
        except (ConfigError, FileError):  # missing or not a token: a new one
            made = new_token()
            write_token(files.token, made)
    if owner is not None and os.geteuid() == 0:
        _give([*created, files.settings, files.token], owner)
    return made


def _give(paths: list[Path], owner: str) -> None:
    """Give the folders made and the files to the user the service runs as (root installs)."""
    import pwd

    from poppy_core.files import file_error

    entry = pwd.getpwnam(owner)
    for path in paths:
        if path.exists():
            try:
                os.chown(path, entry.pw_uid, entry.pw_gid)
            except OSError as exc:
                raise file_error(exc, path, "give to its user") from None
