"""Read and write robot configs: pypot JSON or our YAML (written by ``poppy_core.files``)."""

from __future__ import annotations

import json
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import yaml

from poppy_core.documents import CONFIG_LIMITS, parse_json, parse_yaml, read_limited
from poppy_core.files import write_file
from poppy_core.robot.config import RobotConfig
from poppy_core.robot.config_format import config_error

JSON_SUFFIXES = (".json",)
YAML_SUFFIXES = (".yaml", ".yml")


def _looks_like_json(text: str) -> bool:
    return text.lstrip().startswith(("{", "["))


def parse_config_text(text: str, source: str, *, fmt: str | None = None) -> Any:
    """Parse a config document (JSON or YAML) into plain data, within ``CONFIG_LIMITS``.

    Args:
        text: The document.
        source: The file name for error messages.
        fmt: "json" or "yaml"; guessed from the content when None.

    Returns:
        The parsed data (not validated).

    Raises:
        ConfigError: On a syntax error (naming the line and column), or a document too large,
            too deep or cyclic (a YAML alias bomb is refused before it expands).
    """
    kind = fmt or ("json" if _looks_like_json(text) else "yaml")
    if kind == "json":
        return parse_json(text, source, CONFIG_LIMITS)
    return parse_yaml(text, source, CONFIG_LIMITS)


def _format_of(path: Path, text: str | None = None) -> str | None:
    suffix = path.suffix.lower()
    if suffix in JSON_SUFFIXES:
        return "json"
    if suffix in YAML_SUFFIXES:
        return "yaml"
    if text is not None:
        return "json" if _looks_like_json(text) else "yaml"
    return None


def load_config(path: str | os.PathLike[str]) -> RobotConfig:
    """Load a robot config: pypot JSON (``.json``) or our YAML (``.yaml``/``.yml``).

    Other extensions are recognised by their content (a leading ``{`` means JSON).

    Args:
        path: The file to read.

    Returns:
        The validated config.

    Raises:
        ConfigError: The file cannot be read (missing, not a regular file, over 1 MiB, not
            UTF-8), has a syntax error, is too deep or large, or has invalid fields.
    """
    file = Path(path)
    source = str(path)
    raw = read_limited(file, CONFIG_LIMITS.max_bytes, "config")
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise config_error(
            source,
            "",
            None,
            f"cannot read: not UTF-8 text ({exc.reason} at byte {exc.start})",
            show_value=False,
        ) from None
    data = parse_config_text(text, source, fmt=_format_of(file, text))
    return RobotConfig.from_dict(data, source=source).with_folder(file.resolve().parent)


ConfigSource = RobotConfig | Mapping[str, Any] | str | os.PathLike[str]
"""What the factories take as a config: a RobotConfig, a pypot-style dict, or a file path."""

DICT_SOURCE = "<config dict>"


def as_config(config: ConfigSource) -> RobotConfig:
    """A validated ``RobotConfig`` from a config, a dict (pypot's ``from_config(my_config)``) or a
    JSON/YAML file path.

    Raises:
        ConfigError: an invalid config, an unreadable file, or another kind of object.
    """
    if isinstance(config, RobotConfig):
        return config
    if isinstance(config, Mapping):
        return RobotConfig.from_dict(dict(config), source=DICT_SOURCE)
    if isinstance(config, str | os.PathLike):
        return load_config(config)
    raise config_error(
        DICT_SOURCE,
        "",
        None,
        f"the config must be a RobotConfig, a mapping or a file path, not {type(config).__name__}",
        show_value=False,
    )


class _ConfigDumper(yaml.SafeDumper):
    """Block style, except lists of plain values which read best inline: ``[-90.0, 90.0]``."""


def _represent_list(dumper: yaml.SafeDumper, data: list[Any]) -> yaml.Node:
    flow = all(isinstance(item, (str, int, float, bool)) or item is None for item in data)
    return dumper.represent_sequence("tag:yaml.org,2002:seq", data, flow_style=flow)


# PyYAML writes these raw in plain or block scalars and reads them back as line breaks;
# the double-quoted style escapes them.
_LINE_BREAK_LIKE = frozenset("\x85\u2028\u2029")


def _represent_str(dumper: yaml.SafeDumper, data: str) -> yaml.Node:
    if any(char in _LINE_BREAK_LIKE for char in data):
        return dumper.represent_scalar("tag:yaml.org,2002:str", data, style='"')
    return dumper.represent_str(data)


_ConfigDumper.add_representer(list, _represent_list)
_ConfigDumper.add_representer(str, _represent_str)


def config_to_text(config: RobotConfig, fmt: str) -> str:
    """Serialise a config: "json" gives pypot JSON, "yaml" our YAML (profile header kept).

    Args:
        config: The config.
        fmt: "json" or "yaml".

    Returns:
        The document text, ending with a newline.
    """
    if fmt == "json":
        return json.dumps(config.to_pypot_dict(), indent=2, ensure_ascii=False) + "\n"
    dumped: str = yaml.dump(
        config.to_dict(),
        Dumper=_ConfigDumper,
        sort_keys=False,
        allow_unicode=True,
        default_flow_style=False,
        width=120,
    )
    return dumped


def dump_config(config: RobotConfig, path: str | os.PathLike[str], *, replace: bool = True) -> Path:
    """Write a config atomically; ``.json`` gives pypot JSON, ``.yaml``/``.yml`` our YAML.

    Args:
        config: The config to write.
        path: The target file; its extension picks the format (YAML for others).
        replace: replace an existing regular file (the CLI passes its ``--force``).

    Returns:
        The path written.

    Raises:
        FileError: The file cannot be written (missing folder, full disk...) or is refused (it
            exists without ``replace``, or is not a regular file); see ``poppy_core.files``.
    """
    file = Path(path)
    text = config_to_text(config, _format_of(file) or "yaml")
    return write_file(file, text, replace=replace)
