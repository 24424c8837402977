"""Config files: format by extension or content, atomic writes, readable YAML."""

from __future__ import annotations

import json
import os
import stat
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from poppy_core.errors import FileError
from poppy_core.robot import RobotConfig, dump_config, load_config

Data = dict[str, Any]


def _config(base_config: Callable[[], Data]) -> RobotConfig:
    return RobotConfig.from_dict(base_config())


def _leftovers(directory: Path) -> list[str]:
    return sorted(p.name for p in directory.iterdir() if p.name.endswith(".tmp"))


@pytest.mark.parametrize("boom_at", ["fsync", "replace"])
def test_failed_dump_leaves_old_file_intact(
    tmp_path: Path,
    base_config: Callable[[], Data],
    monkeypatch: pytest.MonkeyPatch,
    boom_at: str,
) -> None:
    target = tmp_path / "robot.yaml"
    target.write_text("old content\n", encoding="utf-8")

    def boom(*args: object) -> None:
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(os, boom_at, boom)
    with pytest.raises(FileError, match=r"robot.yaml: no space left on the device"):
        dump_config(_config(base_config), target)
    assert target.read_text(encoding="utf-8") == "old content\n"
    assert _leftovers(tmp_path) == []


def test_failed_serialisation_touches_nothing(
    tmp_path: Path, base_config: Callable[[], Data], monkeypatch: pytest.MonkeyPatch
) -> None:
    target = tmp_path / "robot.json"
    target.write_text("{}", encoding="utf-8")

    def boom(*args: object, **kwargs: object) -> str:
        raise RuntimeError("serialiser crashed")

    monkeypatch.setattr(json, "dumps", boom)
    with pytest.raises(RuntimeError):
        dump_config(_config(base_config), target)
    assert target.read_text(encoding="utf-8") == "{}"
    assert _leftovers(tmp_path) == []


def test_dump_replaces_and_keeps_mode(tmp_path: Path, base_config: Callable[[], Data]) -> None:
    target = tmp_path / "robot.yaml"
    target.write_text("old\n", encoding="utf-8")
    os.chmod(target, 0o600)
    dump_config(_config(base_config), target)
    assert stat.S_IMODE(target.stat().st_mode) == 0o600
    assert load_config(target) == _config(base_config)
    assert _leftovers(tmp_path) == []


def test_new_file_mode(tmp_path: Path, base_config: Callable[[], Data]) -> None:
    target = tmp_path / "new.yaml"
    dump_config(_config(base_config), target)
    assert stat.S_IMODE(target.stat().st_mode) == 0o644


def test_dump_into_missing_folder(tmp_path: Path, base_config: Callable[[], Data]) -> None:
    with pytest.raises(FileError, match="the folder does not exist: create it first"):
        dump_config(_config(base_config), tmp_path / "no" / "robot.yaml")
    assert not (tmp_path / "no").exists()


def test_format_by_extension(tmp_path: Path, base_config: Callable[[], Data]) -> None:
    config = _config(base_config)
    for name in ("a.json", "b.yaml", "c.yml", "d.conf"):
        dump_config(config, tmp_path / name)
    assert json.loads((tmp_path / "a.json").read_text(encoding="utf-8")) == base_config()
    yaml_text = (tmp_path / "b.yaml").read_text(encoding="utf-8")
    assert "angle_limit: [-90.0, 90.0]" in yaml_text
    assert "attached_motors: [arm]" in yaml_text
    assert (tmp_path / "c.yml").read_text(encoding="utf-8") == yaml_text
    assert (tmp_path / "d.conf").read_text(encoding="utf-8") == yaml_text
    for name in ("a.json", "b.yaml", "c.yml", "d.conf"):
        assert load_config(tmp_path / name) == config


def test_format_by_content(tmp_path: Path, base_config: Callable[[], Data]) -> None:
    path = tmp_path / "robot.cfg"
    path.write_text(json.dumps(base_config()), encoding="utf-8")
    assert load_config(path) == _config(base_config)


def test_pypot_json_drops_profile_header_yaml_keeps_it(
    tmp_path: Path, base_config: Callable[[], Data]
) -> None:
    data = base_config()
    data["profile"] = {
        "name": "mine",
        "description": "a test robot",
        "kind": "arm",
        "source": "here",
    }
    config = RobotConfig.from_dict(data)
    dump_config(config, tmp_path / "r.json")
    dump_config(config, tmp_path / "r.yaml")
    assert "profile" not in json.loads((tmp_path / "r.json").read_text(encoding="utf-8"))
    again = load_config(tmp_path / "r.yaml")
    assert again.profile is not None and again.profile.name == "mine"
    assert again == config
