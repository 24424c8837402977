"""The public Poppy configs and our profiles load, round-trip, and resolve groups."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
import yaml

from poppy_core.errors import ConfigError
from poppy_core.robot import RobotConfig, config_to_text, dump_config, load_config


def test_public_config_loads_unchanged(public_config: tuple[Path, dict[str, Any]]) -> None:
    path, raw = public_config
    config = load_config(path)
    assert set(config.motors) == set(raw["motors"])
    for name, motor in config.motors.items():
        source = raw["motors"][name]
        assert motor.id == source["id"]
        assert motor.type == source["type"]
        assert motor.orientation == source["orientation"]
        assert motor.offset == source["offset"]
        assert list(motor.angle_limit) == source["angle_limit"]
    assert config.to_dict()["sensors"] == raw["sensors"]
    assert config.motorgroups == raw["motorgroups"]


def test_public_config_json_round_trip(public_config: tuple[Path, dict[str, Any]]) -> None:
    path, raw = public_config
    assert load_config(path).to_pypot_dict() == raw


def test_public_config_json_file_round_trip(
    public_config: tuple[Path, dict[str, Any]], tmp_path: Path
) -> None:
    path, raw = public_config
    out = tmp_path / "copy.json"
    dump_config(load_config(path), out)
    assert json.loads(out.read_text(encoding="utf-8")) == raw


def test_public_config_yaml_round_trip(
    public_config: tuple[Path, dict[str, Any]], tmp_path: Path
) -> None:
    path, _ = public_config
    config = load_config(path)
    out = tmp_path / "robot.yaml"
    dump_config(config, out)
    again = load_config(out)
    assert again == config
    assert again.to_pypot_dict() == config.to_pypot_dict()


def test_unknown_keys_are_kept(base_config: Any) -> None:
    data = base_config()
    data["motors"]["m1"]["broken"] = True
    data["controllers"]["upper"]["use_dummy_io"] = False
    data["sensors"] = {"cam": {"type": "OpenCVCamera", "index": -1, "nested": {"a": [1, 2]}}}
    data["extra_top_level"] = {"anything": 1}
    config = RobotConfig.from_dict(data)
    assert config.to_pypot_dict() == data
    assert RobotConfig.from_dict(yaml.safe_load(config_to_text(config, "yaml"))) == config


def test_pypot_dict_has_the_keys_pypot_requires(base_config: Any) -> None:
    data = base_config()
    del data["motors"]["m1"]["offset"]
    del data["motors"]["m1"]["orientation"]
    del data["controllers"]["upper"]["sync_read"]
    del data["controllers"]["upper"]["port"]
    del data["motorgroups"]
    data["controllers"]["upper"]["attached_motors"] = ["m1", "m2"]
    out = RobotConfig.from_dict(data).to_pypot_dict()
    assert out["motors"]["m1"]["offset"] == 0.0
    assert out["motors"]["m1"]["orientation"] == "direct"
    assert out["controllers"]["upper"]["sync_read"] is False
    assert out["controllers"]["upper"]["port"] == "auto"
    assert out["motorgroups"] == {}


def test_defaults(base_config: Any) -> None:
    config = RobotConfig.from_dict(base_config())
    upper = config.controllers["upper"]
    assert (upper.protocol, upper.baudrate, upper.syncloop) == (1, 1_000_000, "BaseDxlController")
    motor = config.motors["m1"]
    assert motor.return_delay_time is None and motor.pid is None and not motor.wheel_mode


def test_optional_motor_fields(base_config: Any) -> None:
    data = base_config()
    data["motors"]["m1"].update(
        return_delay_time=0, max_torque=80, pid=[4, 0, 0.5], wheel_mode=True
    )
    config = RobotConfig.from_dict(data)
    motor = config.motors["m1"]
    assert (motor.return_delay_time, motor.max_torque, motor.pid, motor.wheel_mode) == (
        0,
        80.0,
        (4.0, 0.0, 0.5),
        True,
    )
    assert config.to_pypot_dict() == data


def test_resolve_group_flattens_in_order() -> None:
    config = load_config(Path(__file__).parent / "data" / "poppy_humanoid.json")
    assert config.resolve_group("l_leg") == [
        "l_hip_x",
        "l_hip_z",
        "l_hip_y",
        "l_knee_y",
        "l_ankle_y",
    ]
    assert config.resolve_group("arms")[:4] == [
        "l_shoulder_y",
        "l_shoulder_x",
        "l_arm_z",
        "l_elbow_y",
    ]
    assert config.resolve_group("head_z") == ["head_z"]
    lower = config.motors_of_controller("lower_body_controller")
    upper = config.motors_of_controller("upper_body_controller")
    assert len(lower) == 10 and len(upper) == 15
    assert not set(lower) & set(upper)
    assert config.controller_of("r_knee_y") == "lower_body_controller"
    assert config.unattached_motors() == []


def test_resolve_group_removes_repeats(base_config: Any) -> None:
    data = base_config()
    data["motorgroups"]["twice"] = ["arm", "m1", "all"]
    config = RobotConfig.from_dict(data)
    assert config.resolve_group("twice") == ["m1", "m2", "m3"]


def test_unknown_group_and_controller_lookups(base_config: Any) -> None:
    config = RobotConfig.from_dict(base_config())
    with pytest.raises(ConfigError, match="no such group"):
        config.resolve_group("legs")
    with pytest.raises(ConfigError, match=r"no such controller \(controllers: lower, upper\)"):
        config.motors_of_controller("middle")
