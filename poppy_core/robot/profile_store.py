"""Write a user profile (``<user config dir>/poppy/profiles/<name>/profile.yaml``) safely.

The new file is written atomically (a reader sees the old content or the new, never half), and
the file it replaces is first kept beside it as ``profile.yaml.bak`` (atomically too). A write
cut short at any point leaves the previous profile in place.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from poppy_core.errors import ConfigError, FileError
from poppy_core.files import write_file
from poppy_core.robot.calibration import Calibration
from poppy_core.robot.config import RobotConfig
from poppy_core.robot.config_io import config_to_text
from poppy_core.robot.profiles import PROFILE_FILE, user_profile_dir

BACKUP_SUFFIX = ".bak"
_NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]{0,63}$")


@dataclass(frozen=True)
class SavedProfile:
    """Where a profile was written, and where the file it replaced was kept (None: new)."""

    path: Path
    backup: Path | None


def check_profile_name(name: str) -> str:
    """A profile name usable as a folder name (letters, digits, ``_ . -``).

    Raises:
        ConfigError: any other name.
    """
    if not _NAME.match(name) or name in (".", ".."):
        raise ConfigError(
            f"{name!r} cannot be a profile name: use letters, digits, '_', '.' and '-'",
            field="profile.name",
            value=name,
        )
    return name


def user_profile_path(name: str, user_dir: Path | None = None) -> Path:
    """The file a user profile called ``name`` lives in."""
    root = user_dir if user_dir is not None else user_profile_dir()
    return root / check_profile_name(name) / PROFILE_FILE


def save_user_profile(
    config: RobotConfig, name: str, user_dir: Path | None = None, *, comment: str = ""
) -> SavedProfile:
    """Write ``config`` as the user profile ``name``, keeping the previous file as a backup.

    Args:
        config: the config (its header's name should be ``name``).
        name: the profile's name (its folder).
        user_dir: the user's profile folder; ``user_profile_dir()`` when None.
        comment: lines written as a ``#`` comment at the top of the file.

    Returns:
        The paths written.

    Raises:
        ConfigError: a bad name, or a file that cannot be written (the previous one is intact).
    """
    path = user_profile_path(name, user_dir)
    text = "".join(f"# {line}\n" for line in comment.splitlines()) + config_to_text(config, "yaml")
    backup: Path | None = None
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        if path.exists():
            backup = path.with_name(path.name + BACKUP_SUFFIX)
            write_file(backup, path.read_bytes(), replace=True)
        write_file(path, text, replace=True)
    except FileError as exc:
        raise ConfigError(str(exc), file=str(path)) from None
    except OSError as exc:
        raise ConfigError(f"{path}: cannot write: {exc.strerror or exc}", file=str(path)) from None
    return SavedProfile(path, backup)


def save_calibration(
    config: RobotConfig, calibration: Calibration, name: str, *, by: str
) -> SavedProfile:
    """Write ``config`` with ``calibration`` applied as the user profile ``name``.

    Args:
        config: the robot's config before the calibration.
        calibration: what the session recorded.
        name: the user profile written.
        by: what calibrated it, for the file's header comment (``poppy calibrate``).

    Raises:
        ConfigError: a bad name, or a file that cannot be written (the previous one is intact).
    """
    base = config.profile.name if config.profile is not None else "a config"
    return save_user_profile(
        calibration.apply(config, name),
        name,
        comment=(
            f"Profile {name!r}: {base} calibrated by `{by}` on {calibration.created}.\n"
            "The file it replaced, if any, is kept beside it as profile.yaml.bak."
        ),
    )
