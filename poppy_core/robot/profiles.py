"""Robot profiles: the installed ones (Ergo Jr, Torso, Humanoid) and the user's own."""

from __future__ import annotations

import difflib
import logging
import re
from dataclasses import dataclass
from pathlib import Path

import platformdirs

from poppy_core.documents import CONFIG_LIMITS, parse_yaml, read_limited
from poppy_core.errors import ConfigError
from poppy_core.robot.config import RobotConfig
from poppy_core.robot.config_format import config_error
from poppy_core.robot.config_io import load_config

logger = logging.getLogger(__name__)

PROFILE_FILE = "profile.yaml"
"""Each profile is a folder holding this file (and, later, its simulation model)."""
_SOURCE = "profiles"


@dataclass(frozen=True)
class ProfileInfo:
    """What ``list_profiles`` tells about one profile (read from its header)."""

    name: str
    """The folder name, e.g. ``ergo-jr``; what ``load_profile`` takes."""
    kind: str
    description: str
    source: str
    directory: Path
    """The profile's folder (the place for files that go with it, such as a simulation model)."""
    file: Path
    user: bool
    """True for a profile from the user's config folder."""


def user_profile_dir() -> Path:
    """The folder for the user's own profiles: ``<user config dir>/poppy/profiles``.

    On Linux that is ``$XDG_CONFIG_HOME/poppy/profiles`` (``~/.config/poppy/profiles``).
    """
    return Path(platformdirs.user_config_dir("poppy")) / "profiles"


def installed_profile_dir() -> Path | None:
    """The profiles shipped with poppy, or None when they cannot be found.

    An installed wheel carries them in ``poppy_core/_profiles``; a source checkout has them in
    ``profiles/`` next to ``pyproject.toml``.
    """
    package_dir = Path(__file__).resolve().parents[1]  # poppy_core/
    bundled = package_dir / "_profiles"
    if bundled.is_dir():
        return bundled
    checkout = package_dir.parent
    if (checkout / "pyproject.toml").is_file() and (checkout / "profiles").is_dir():
        return checkout / "profiles"
    return None


def profile_dirs(user_dir: Path | None = None) -> list[Path]:
    """The existing profile folders, highest priority first (the user's before installed ones).

    Args:
        user_dir: The user's profile folder; ``user_profile_dir()`` when None.

    Returns:
        Folders that exist; a profile in an earlier folder hides one of the same name later.
    """
    candidates = [user_dir if user_dir is not None else user_profile_dir()]
    installed = installed_profile_dir()
    if installed is not None:
        candidates.append(installed)
    found: list[Path] = []
    for directory in candidates:
        if directory.is_dir() and directory.resolve() not in {d.resolve() for d in found}:
            found.append(directory)
    return found


def profile_key(name: str) -> str:
    """Compare key for profile names: "Poppy_Ergo-Jr", "ergo_jr" and "ergo-jr" all match."""
    key = re.sub(r"[^a-z0-9]", "", name.lower())
    return key.removeprefix("poppy") or key


def _read_info(file: Path, user: bool) -> ProfileInfo | None:
    try:
        data = parse_yaml(
            read_limited(file, CONFIG_LIMITS.max_bytes, "profile"), str(file), CONFIG_LIMITS
        )
    except ConfigError as exc:
        logger.warning("skipping profile %s: %s", file, exc)
        return None
    header = data.get("profile") if isinstance(data, dict) else None
    header = header if isinstance(header, dict) else {}

    def text(key: str) -> str:
        value = header.get(key, "")
        return value if isinstance(value, str) else str(value)

    return ProfileInfo(
        name=file.parent.name,
        kind=text("kind"),
        description=text("description"),
        source=text("source"),
        directory=file.parent,
        file=file,
        user=user,
    )


def list_profiles(user_dir: Path | None = None) -> list[ProfileInfo]:
    """The available profiles, by name; a user profile replaces an installed one of that name.

    Args:
        user_dir: The user's profile folder; ``user_profile_dir()`` when None.

    Returns:
        One entry per profile name, sorted by name. Unreadable files are skipped (logged).
    """
    user_root = user_dir if user_dir is not None else user_profile_dir()
    chosen: dict[str, ProfileInfo] = {}
    for directory in profile_dirs(user_dir):
        is_user = directory.resolve() == user_root.resolve()
        for file in sorted(directory.glob(f"*/{PROFILE_FILE}")):
            key = profile_key(file.parent.name)
            if key in chosen:
                continue
            info = _read_info(file, is_user)
            if info is not None:
                chosen[key] = info
    return sorted(chosen.values(), key=lambda info: info.name)


def find_profile(name: str, user_dir: Path | None = None) -> ProfileInfo:
    """Find a profile by name, ignoring case, "_" versus "-" and a "poppy-" prefix.

    Args:
        name: E.g. "ergo-jr", "ergo_jr", "Poppy-Ergo-Jr".
        user_dir: The user's profile folder; ``user_profile_dir()`` when None.

    Returns:
        The profile's info.

    Raises:
        ConfigError: No profile of that name; the message lists the known names.
    """
    profiles = list_profiles(user_dir)
    for info in profiles:
        if profile_key(info.name) == profile_key(name):
            return info
    known = ", ".join(info.name for info in profiles) or "none installed"
    close = difflib.get_close_matches(
        profile_key(name), [profile_key(info.name) for info in profiles], n=1, cutoff=0.6
    )
    hint = "".join(
        f"did you mean {info.name}? "
        for info in profiles
        if close and profile_key(info.name) == close[0]
    )
    raise config_error(_SOURCE, "profile", name, f"unknown profile; {hint}known: {known}")


def profile_folders(name: str, user_dir: Path | None = None) -> list[Path]:
    """Every folder holding a profile called ``name``, the user's first.

    A user profile named like an installed one (a calibrated ``ergo-jr``) hides it, but files
    that go with the robot (its URDF, its simulation model) are still found in the installed
    folder.
    """
    key = profile_key(name)
    return [
        file.parent
        for directory in profile_dirs(user_dir)
        for file in sorted(directory.glob(f"*/{PROFILE_FILE}"))
        if profile_key(file.parent.name) == key
    ]


def load_profile(name: str, user_dir: Path | None = None) -> RobotConfig:
    """Load and validate a profile's config.

    Args:
        name: The profile name (see ``find_profile`` for the accepted spellings).
        user_dir: The user's profile folder; ``user_profile_dir()`` when None.

    Returns:
        The config; its ``profile`` attribute holds the header.

    Raises:
        ConfigError: Unknown profile, or an invalid profile file.
    """
    return load_config(find_profile(name, user_dir).file)
