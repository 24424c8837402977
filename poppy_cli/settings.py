"""User settings for `poppy`: a YAML file (profile, port) overridden by env vars and options."""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

SETTINGS_KEYS = ("profile", "port")
PROFILE_ENV = "POPPY_PROFILE"
PORT_ENV = "POPPY_PORT"


@dataclass(frozen=True)
class Settings:
    """The robot defaults: a profile name and a port, each None when unset."""

    profile: str | None = None
    port: str | None = None


def settings_file() -> Path:
    """The user settings file: ``<user config dir>/poppy/config.yaml``."""
    import platformdirs

    return Path(platformdirs.user_config_dir("poppy")) / "config.yaml"


def load_settings(path: Path | None = None) -> Settings:
    """Read the user settings file (a missing file gives empty settings).

    Args:
        path: the file; ``settings_file()`` when None.

    Raises:
        ConfigError: the file is not a YAML mapping of known keys with text values.
    """
    from poppy_core.documents import SETTINGS_LIMITS, parse_yaml, read_limited
    from poppy_core.errors import ConfigError

    file = path if path is not None else settings_file()
    if not file.exists() and not file.is_symlink():
        return Settings()
    data = parse_yaml(
        read_limited(file, SETTINGS_LIMITS.max_bytes, "settings file"), str(file), SETTINGS_LIMITS
    )
    if data is None:
        return Settings()
    if not isinstance(data, dict):
        raise ConfigError(
            f"{file}: must be a mapping with the keys {', '.join(SETTINGS_KEYS)}", file=str(file)
        )
    values: dict[str, str | None] = {}
    for key, value in data.items():
        if key not in SETTINGS_KEYS:
            raise ConfigError(
                f"{file}: unknown key {key!r} (keys: {', '.join(SETTINGS_KEYS)})",
                file=str(file),
                field=str(key),
            )
        if value is not None and not isinstance(value, str):
            raise ConfigError(f"{file}: {key} must be text", file=str(file), field=key)
        values[key] = value or None
    return Settings(profile=values.get("profile"), port=values.get("port"))


def resolve(profile: str | None = None, port: str | None = None) -> Settings:
    """The effective settings: options first, then POPPY_PROFILE/POPPY_PORT, then the file."""
    env_profile = os.environ.get(PROFILE_ENV) or None
    env_port = os.environ.get(PORT_ENV) or None
    chosen_profile = profile or env_profile
    chosen_port = port or env_port
    if chosen_profile is None or chosen_port is None:
        stored = load_settings()
        chosen_profile = chosen_profile or stored.profile
        chosen_port = chosen_port or stored.port
    return Settings(profile=chosen_profile, port=chosen_port)


def check_key(key: str) -> str:
    """``key`` if it is a setting.

    Raises:
        ConfigError: an unknown key (the settings listed).
    """
    from poppy_core.errors import ConfigError

    if key not in SETTINGS_KEYS:
        raise ConfigError(
            f"unknown setting {key!r} (settings: {', '.join(SETTINGS_KEYS)})", field=key
        )
    return key


def check_setting(key: str, value: str) -> str:
    """``value`` checked for ``key``: the profile must exist (its name as listed), the port be
    non-blank text.

    Raises:
        ConfigError: an unknown key, an unknown profile (known names listed), a blank value.
    """
    from poppy_core.errors import ConfigError

    check_key(key)
    text = value.strip()
    if not text:
        raise ConfigError(f"{key}: give a value (`poppy config unset {key}` removes it)", field=key)
    if key == "profile":
        from poppy_core.robot.profiles import find_profile

        return find_profile(text).name
    return text


def save_settings(settings: Settings, path: Path | None = None) -> Path:
    """Write the user settings file atomically (``poppy_core.files``), unset keys left out."""
    import yaml

    from poppy_core.files import write_file

    file = path if path is not None else settings_file()
    values = {key: getattr(settings, key) for key in SETTINGS_KEYS if getattr(settings, key)}
    text = yaml.safe_dump(values, sort_keys=False) if values else ""
    return write_file(file, text, replace=True, make_folder=True)
