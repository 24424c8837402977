"""Read and write robot configs: pypot JSON or our YAML, with atomic writes."""

from __future__ import annotations

import contextlib
import json
import os
import stat
import tempfile
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import yaml

from poppy_core.robot.config import RobotConfig
from poppy_core.robot.config_format import config_error

JSON_SUFFIXES = (".json",)
YAML_SUFFIXES = (".yaml", ".yml")
NEW_FILE_MODE = 0o644  # rw-r--r--; not derived from the umask (reading it is not thread-safe)


def _looks_like_json(text: str) -> bool:
    return text.lstrip().startswith(("{", "["))


def parse_config_text(text: str, source: str, *, fmt: str | None = None) -> Any:
    """Parse a config document (JSON or YAML) into plain data.

    Args:
        text: The document.
        source: The file name for error messages.
        fmt: "json" or "yaml"; guessed from the content when None.

    Returns:
        The parsed data (not validated).

    Raises:
        ConfigError: On a syntax error, naming the line and column.
    """
    kind = fmt or ("json" if _looks_like_json(text) else "yaml")
    if kind == "json":
        try:
            return json.loads(text)
        except json.JSONDecodeError as exc:
            raise config_error(source, "", None, f"JSON syntax error at line {exc.lineno}, "
                               f"column {exc.colno}: {exc.msg}", show_value=False) from None
    try:
        return yaml.safe_load(text)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""
        problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
        raise config_error(source, "", None, f"YAML syntax error{where}: {problem}",
                           show_value=False) from None


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
        ConfigError: The file cannot be read, has a syntax error, or an invalid field.
    """
    file = Path(path)
    source = str(path)
    try:
        text = file.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
        raise config_error(source, "", None, f"cannot read: {reason}",
                           show_value=False) from None
    data = parse_config_text(text, source, fmt=_format_of(file, text))
    return RobotConfig.from_dict(data, source=source)


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
    raise config_error(DICT_SOURCE, "", None, f"the config must be a RobotConfig, a mapping or a "
                       f"file path, not {type(config).__name__}", show_value=False)


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
    dumped: str = yaml.dump(config.to_dict(), Dumper=_ConfigDumper, sort_keys=False,
                            allow_unicode=True, default_flow_style=False, width=120)
    return dumped


def atomic_write_text(path: Path, text: str) -> None:
    """Write a file so that readers see either the old or the new content, never half of it.

    The text goes to a temporary file in the same folder, is flushed to disk, then renamed
    over the target with ``os.replace``. An existing file keeps its permission bits; a new
    one gets 0o644.

    Args:
        path: The target file.
        text: The full new content.
    """
    directory = path.parent if str(path.parent) else Path(".")
    try:
        mode = stat.S_IMODE(path.stat().st_mode)
    except FileNotFoundError:
        mode = NEW_FILE_MODE
    fd, tmp_name = tempfile.mkstemp(dir=directory, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as handle:
            handle.write(text)
            handle.flush()
            os.fsync(handle.fileno())
        os.chmod(tmp_name, mode)
        os.replace(tmp_name, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp_name)
        raise


def dump_config(config: RobotConfig, path: str | os.PathLike[str]) -> None:
    """Write a config atomically; ``.json`` gives pypot JSON, ``.yaml``/``.yml`` our YAML.

    Args:
        config: The config to write.
        path: The target file; its extension picks the format (YAML for others).

    Raises:
        ConfigError: The file cannot be written.
    """
    file = Path(path)
    text = config_to_text(config, _format_of(file) or "yaml")
    try:
        atomic_write_text(file, text)
    except OSError as exc:
        raise config_error(str(file), "", None, f"cannot write: {exc.strerror or exc}",
                           show_value=False) from None
