"""The appliance's serve options file (Snap!, ZMQ on/off) and its token file.

``poppy service install`` writes both in the service's folder (``POPPY_SERVICE_DIR``, else the
user's config folder ``.../poppy/service``), ``poppy serve --settings FILE --token-file FILE``
reads them at start, and the page's settings write them (then restart ``poppy.service``), so a
change survives restarts. The options file is JSON (``{"snap": false, "zmq": false}``); the token
file holds the token alone on one line, readable by its owner only (mode 600): the token is
never in the unit file nor on a command line that ``ps`` shows. Both are written atomically.
"""

from __future__ import annotations

import json
import logging
import os
import re
import secrets
import stat
from dataclasses import asdict, dataclass
from pathlib import Path

from poppy_core.errors import ConfigError
from poppy_core.files import file_error, write_file

logger = logging.getLogger(__name__)

SERVICE_DIR_ENV = "POPPY_SERVICE_DIR"
OPTIONS_NAME = "serve.json"
TOKEN_NAME = "token"
OPTIONS = ("snap", "zmq")
"""The options the file turns on or off (``poppy serve --snap``, ``--zmq``)."""
TOKEN = re.compile(r"[!-~]{12,128}")
"""A token: 12 to 128 visible ASCII characters (no space): it fits a header and a URL."""
TOKEN_RULE = "a token is 12 to 128 visible ASCII characters, no space (e.g. openssl rand -hex 16)"
SECRET_MODE = 0o600
MAX_BYTES = 4096


@dataclass(frozen=True)
class ServeOptions:
    """The servers of ``poppy.service`` the page turns on or off."""

    snap: bool = False
    zmq: bool = False


def service_folder() -> Path:
    """The service's files: ``POPPY_SERVICE_DIR``, else ``<user config>/poppy/service``."""
    given = os.environ.get(SERVICE_DIR_ENV)
    if given:
        return Path(given)
    import platformdirs

    return Path(platformdirs.user_config_dir("poppy")) / "service"


def _read(path: Path, what: str) -> str:
    try:
        with path.open("rb") as stream:
            data = stream.read(MAX_BYTES + 1)
    except FileNotFoundError:
        raise ConfigError(
            f"{what} {path} does not exist: `poppy service install` writes it"
        ) from None
    except OSError as exc:
        raise file_error(exc, path, "read") from None
    if len(data) > MAX_BYTES:
        raise ConfigError(f"{what} {path} is larger than {MAX_BYTES} bytes: it is not one")
    return data.decode("utf-8", errors="replace")


def read_options(path: Path) -> ServeOptions:
    """The options of ``path`` (a missing file: all off, as the flags say).

    Raises:
        ConfigError: not a JSON object of ``snap``/``zmq`` true or false.
    """
    if not path.exists():
        return ServeOptions()
    text = _read(path, "the settings file")
    try:
        found = json.loads(text)
    except ValueError:
        raise ConfigError(f"the settings file {path} is not JSON: rewrite it") from None
    if not isinstance(found, dict):
        raise ConfigError(f"the settings file {path} is not a JSON object: rewrite it")
    unknown = sorted(set(found) - set(OPTIONS))
    if unknown or not all(isinstance(v, bool) for v in found.values()):
        raise ConfigError(
            f"the settings file {path} holds {', '.join(unknown) or 'a value'} it should not: "
            f"only {' and '.join(OPTIONS)}, each true or false"
        )
    return ServeOptions(**found)


def write_options(path: Path, options: ServeOptions) -> None:
    """Write ``options`` to ``path`` atomically (its folder made when missing)."""
    text = json.dumps(asdict(options), indent=2) + "\n"
    write_file(path, text, replace=True, make_folder=True, mode=0o644)


def check_token(text: str) -> str:
    """``text`` as a token, or ValueError with the rule."""
    if not TOKEN.fullmatch(text):
        raise ValueError(TOKEN_RULE)
    return text


def new_token() -> str:
    """A random token (128 bits, URL-safe)."""
    return secrets.token_urlsafe(16)


def read_token(path: Path) -> str:
    """The token in ``path`` (its first line, stripped).

    Raises:
        ConfigError: the file is missing, empty or not a token.
        FileError: it cannot be read.
    """
    text = _read(path, "the token file").strip()
    try:
        token = check_token(text)
    except ValueError as exc:
        raise ConfigError(f"the token file {path} holds no valid token: {exc}") from None
    try:
        if stat.S_IMODE(path.stat().st_mode) & 0o077:
            logger.warning("the token file %s is readable by others: chmod 600 %s", path, path)
    except OSError:
        pass
    return token


def write_token(path: Path, token: str) -> None:
    """Write ``token`` to ``path`` atomically, readable by its owner only."""
    check_token(token)
    folder = path.parent
    if not folder.exists():
        try:
            folder.mkdir(mode=0o700, parents=True)
        except OSError as exc:
            raise file_error(exc, folder, "create") from None
    write_file(path, token + "\n", replace=True, mode=SECRET_MODE)
