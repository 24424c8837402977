"""Each invalid config gives a one-line ConfigError naming the file, field path, value, reason."""

from __future__ import annotations

import json
import logging
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from poppy_core.errors import ConfigError
from poppy_core.motion.chains import kinematics_spec
from poppy_core.robot import RobotConfig, load_config

Data = dict[str, Any]


def _set(path: str, value: Any) -> Callable[[Data], None]:
    keys = path.split(".")

    def mutate(data: Data) -> None:
        node = data
        for key in keys[:-1]:
            node = node[key]
        node[keys[-1]] = value

    return mutate


def _delete(path: str) -> Callable[[Data], None]:
    keys = path.split(".")

    def mutate(data: Data) -> None:
        node = data
        for key in keys[:-1]:
            node = node[key]
        del node[keys[-1]]

    return mutate


CASES: list[tuple[str, Callable[[Data], None], str]] = [
    (
        "limit order",
        _set("motors.m3.angle_limit", [90, -90]),
        "robot.yaml: motors.m3.angle_limit = [90, -90]: min must be below max",
    ),
    (
        "limit equal",
        _set("motors.m3.angle_limit", [10.5, 10.5]),
        "robot.yaml: motors.m3.angle_limit = [10.5, 10.5]: min must be below max",
    ),
    (
        "limit shape",
        _set("motors.m3.angle_limit", [1, 2, 3]),
        "robot.yaml: motors.m3.angle_limit = [1, 2, 3]: must be [min, max] in degrees",
    ),
    (
        "limit not a number",
        _set("motors.m3.angle_limit", [-10, "90"]),
        'robot.yaml: motors.m3.angle_limit[1] = "90": must be a valid number',
    ),
    (
        "id too big",
        _set("motors.m2.id", 254),
        "robot.yaml: motors.m2.id = 254: ID must be in 0-253 (254 is broadcast)",
    ),
    (
        "id negative",
        _set("motors.m2.id", -1),
        "robot.yaml: motors.m2.id = -1: ID must be in 0-253 (254 is broadcast)",
    ),
    (
        "id as string",
        _set("motors.m2.id", "2"),
        'robot.yaml: motors.m2.id = "2": must be a valid integer',
    ),
    ("id missing", _delete("motors.m2.id"), "robot.yaml: motors.m2.id: missing (required)"),
    (
        "orientation",
        _set("motors.m1.orientation", "sideways"),
        "robot.yaml: motors.m1.orientation = \"sideways\": must be 'direct' or 'indirect'",
    ),
    (
        "protocol",
        _set("controllers.upper.protocol", 3),
        "robot.yaml: controllers.upper.protocol = 3: must be 1 or 2",
    ),
    (
        "baudrate",
        _set("controllers.upper.baudrate", 0),
        "robot.yaml: controllers.upper.baudrate = 0: must be a positive number of bits/s",
    ),
    (
        "sync_read",
        _set("controllers.upper.sync_read", "yes"),
        'robot.yaml: controllers.upper.sync_read = "yes": must be a valid boolean',
    ),
    (
        "max torque",
        _set("motors.m1.max_torque", 120),
        "robot.yaml: motors.m1.max_torque = 120: must be a percentage in 0-100",
    ),
    (
        "return delay",
        _set("motors.m1.return_delay_time", 600),
        "robot.yaml: motors.m1.return_delay_time = 600: must be in 0-508 µs",
    ),
    (
        "pid shape",
        _set("motors.m1.pid", [1, 2]),
        "robot.yaml: motors.m1.pid = [1, 2]: must be [p, i, d]",
    ),
    (
        "duplicate id",
        _set("motors.m2.id", 1),
        "robot.yaml: motors.m2.id = 1: duplicate ID on controller 'upper' (also used by 'm1')",
    ),
    (
        "two controllers",
        _set("controllers.lower.attached_motors", ["m3", "m1"]),
        "robot.yaml: controllers.lower.attached_motors[1] = \"m1\": motor 'm1' is already "
        "attached to controller 'upper'",
    ),
    (
        "unknown group member",
        _set("motorgroups.arm", ["m1", "m22"]),
        'robot.yaml: motorgroups.arm[1] = "m22": no motor or group of that name '
        "(did you mean 'm2'?)",
    ),
    (
        "unknown attached name",
        _set("controllers.upper.attached_motors", ["legs"]),
        'robot.yaml: controllers.upper.attached_motors[0] = "legs": no motor or group of that name',
    ),
    (
        "cyclic groups",
        _set("motorgroups.arm", ["m1", "all"]),
        'robot.yaml: motorgroups.arm = ["m1", "all"]: cyclic groups: arm → all → arm',
    ),
    (
        "self cycle",
        _set("motorgroups.loop", ["loop"]),
        'robot.yaml: motorgroups.loop = ["loop"]: cyclic groups: loop → loop',
    ),
    (
        "group named like motor",
        _set("motorgroups.m1", ["m2"]),
        "robot.yaml: motorgroups.m1 = [\"m2\"]: group name 'm1' is already a motor name",
    ),
    (
        "not a mapping",
        _set("motors", ["m1"]),
        'robot.yaml: motors = ["m1"]: must be a valid dictionary',
    ),
]


@pytest.mark.parametrize(("mutate", "expected"), [c[1:] for c in CASES], ids=[c[0] for c in CASES])
def test_error_message(
    base_config: Callable[[], Data], mutate: Callable[[Data], None], expected: str
) -> None:
    data = base_config()
    mutate(data)
    with pytest.raises(ConfigError) as info:
        RobotConfig.from_dict(data, source="robot.yaml")
    assert str(info.value.problems[0]) == expected
    assert str(info.value).startswith(expected)
    assert "\n" not in str(info.value)
    assert info.value.file == "robot.yaml"


def test_error_carries_field_value_reason(base_config: Callable[[], Data]) -> None:
    data = base_config()
    data["motors"]["m3"]["angle_limit"] = [90, -90]
    with pytest.raises(ConfigError) as info:
        RobotConfig.from_dict(data, source="robot.yaml")
    assert info.value.field == "motors.m3.angle_limit"
    assert info.value.value == [90, -90]
    assert info.value.reason == "min must be below max"


def test_unknown_motor_type_lists_known_and_closest(base_config: Callable[[], Data]) -> None:
    data = base_config()
    data["motors"]["m1"]["type"] = "MX-2B"
    with pytest.raises(ConfigError) as info:
        RobotConfig.from_dict(data, source="robot.yaml")
    message = str(info.value)
    assert message.startswith('robot.yaml: motors.m1.type = "MX-2B": unknown motor type')
    assert "did you mean MX-28" in message
    assert "known: " in message and "XL-320" in message and "AX-12" in message
    assert "\n" not in message


def test_protocol_mismatch(base_config: Callable[[], Data]) -> None:
    data = base_config()
    data["motors"]["m1"]["type"] = "XL-320"
    with pytest.raises(ConfigError) as info:
        RobotConfig.from_dict(data, source="robot.yaml")
    assert str(info.value) == (
        "robot.yaml: motors.m1.type = \"XL-320\": a protocol 2 model on controller 'upper', "
        "which uses protocol 1 (set controllers.upper.protocol)"
    )


def test_protocol_2_id_253_refused(base_config: Callable[[], Data]) -> None:
    data = base_config()
    data["controllers"]["lower"]["protocol"] = 2
    data["motors"]["m3"].update(type="XL430-W250", id=253)
    with pytest.raises(ConfigError) as info:
        RobotConfig.from_dict(data, source="robot.yaml")
    assert str(info.value) == (
        "robot.yaml: motors.m3.id = 253: protocol 2 IDs are 0-252 (controller 'lower')"
    )
    data["controllers"]["lower"]["protocol"] = 1
    data["motors"]["m3"]["type"] = "MX-64"
    assert RobotConfig.from_dict(data).motors["m3"].id == 253


def test_same_id_on_two_buses_is_fine(base_config: Callable[[], Data]) -> None:
    config = RobotConfig.from_dict(base_config())
    assert config.motors["m1"].id == config.motors["m3"].id == 1


def test_unattached_motor_is_a_warning(
    base_config: Callable[[], Data], caplog: pytest.LogCaptureFixture
) -> None:
    data = base_config()
    data["motors"]["spare"] = {
        "id": 9,
        "type": "MX-28",
        "orientation": "direct",
        "offset": 0.0,
        "angle_limit": [-10, 10],
    }
    with caplog.at_level(logging.WARNING):
        config = RobotConfig.from_dict(data, source="robot.yaml")
    assert config.unattached_motors() == ["spare"]
    assert config.controller_of("spare") is None
    assert "motors.spare is attached to no controller" in caplog.text


def test_typo_in_key_is_a_warning(
    base_config: Callable[[], Data], caplog: pytest.LogCaptureFixture
) -> None:
    data = base_config()
    data["motors"]["m1"]["max_torq"] = 50
    with caplog.at_level(logging.WARNING):
        config = RobotConfig.from_dict(data, source="robot.yaml")
    assert config.motors["m1"].model_extra == {"max_torq": 50}
    assert "motors.m1.max_torq: unknown key kept as is (did you mean max_torque?)" in caplog.text


def test_top_level_not_a_mapping() -> None:
    with pytest.raises(ConfigError, match=r"^robot.yaml: must be a mapping .* \(got \[1, 2\]\)$"):
        RobotConfig.from_dict([1, 2], source="robot.yaml")


def test_file_errors_name_the_file(tmp_path: Path, base_config: Callable[[], Data]) -> None:
    data = base_config()
    data["motors"]["m3"]["angle_limit"] = [90, -90]
    path = tmp_path / "robot.json"
    path.write_text(json.dumps(data), encoding="utf-8")
    with pytest.raises(ConfigError) as info:
        load_config(path)
    assert str(info.value) == f"{path}: motors.m3.angle_limit = [90, -90]: min must be below max"


def test_yaml_syntax_error_has_line(tmp_path: Path) -> None:
    path = tmp_path / "robot.yaml"
    path.write_text(
        "controllers:\n  upper:\n    port: auto\n   bad: [1, 2\nmotors: {}\n", encoding="utf-8"
    )
    with pytest.raises(ConfigError) as info:
        load_config(path)
    message = str(info.value)
    assert message.startswith(f"{path}: YAML syntax error at line ")
    assert "\n" not in message


def test_json_syntax_error_has_line(tmp_path: Path) -> None:
    path = tmp_path / "robot.json"
    path.write_text('{\n  "controllers": {},\n  "motors": {,}\n}\n', encoding="utf-8")
    with pytest.raises(ConfigError) as info:
        load_config(path)
    assert str(info.value).startswith(f"{path}: JSON syntax error at line 3, column 14: ")


def test_missing_file(tmp_path: Path) -> None:
    path = tmp_path / "nope.yaml"
    with pytest.raises(ConfigError, match=r"nope.yaml: cannot read the config: No such file"):
        load_config(path)


def test_bad_key_type() -> None:
    data: dict[Any, Any] = {"controllers": {1: {"attached_motors": []}}, "motors": {}}
    with pytest.raises(ConfigError) as info:
        RobotConfig.from_dict(data, source="robot.yaml")
    assert str(info.value) == "robot.yaml: controllers.1 = 1: name must be a valid string"


def test_every_problem_is_listed_in_one_pass(base_config: Callable[[], Data]) -> None:
    data = base_config()
    data["motors"]["m2"]["id"] = 1  # duplicate ID on 'upper' (a check across fields)
    data["motors"]["m3"]["angle_limit"] = [90, -90]  # a field error
    data["controllers"]["upper"]["protocol"] = 3  # another field error
    data["motorgroups"]["arm"] = ["m1", "m2", "m22"]  # an unknown group member
    with pytest.raises(ConfigError) as info:
        RobotConfig.from_dict(data, source="robot.yaml")
    lines = [str(p) for p in info.value.problems]
    assert "robot.yaml: motors.m3.angle_limit = [90, -90]: min must be below max" in lines
    assert "robot.yaml: controllers.upper.protocol = 3: must be 1 or 2" in lines
    assert any(line.startswith("robot.yaml: motors.m2.id = 1: duplicate ID") for line in lines)
    assert any(line.startswith('robot.yaml: motorgroups.arm[2] = "m22"') for line in lines)
    assert len(lines) == 4
    assert all("\n" not in line for line in lines)
    assert str(info.value).endswith("(and 3 more problems)")
    assert {p.field for p in info.value.problems} == {
        "motors.m3.angle_limit",
        "controllers.upper.protocol",
        "motors.m2.id",
        "motorgroups.arm[2]",
    }


def test_chains_and_sensors_problems_are_all_listed(base_config: Callable[[], Data]) -> None:
    """The kinematics and sensors sections report every problem, as the rest of the config."""
    data = base_config()
    data["kinematics"] = {"model": "arm.urdf", "chains": {"arm": {"motors": ["m1"], "tip": [0, 0]}}}
    data["sensors"] = {
        "camera": {"type": "OpenCVCamera", "fps": -5},
        "markers": {"type": "MarkerDetector", "cameras": ["nothing"]},
    }
    with pytest.raises(ConfigError) as info:
        RobotConfig.from_dict(data, source="robot.yaml")
    lines = [str(p) for p in info.value.problems]
    assert lines == [
        "robot.yaml: sensors.camera.fps = -5: must be a positive number",
        "robot.yaml: kinematics.chains.arm.tip = [0, 0]: must be [x, y, z] in metres",
        "robot.yaml: sensors.markers.cameras = [\"nothing\"]: 'nothing' is not a camera here",
    ]


def test_a_valid_kinematics_section_reaches_the_leaf_as_plain_data(
    base_config: Callable[[], Data],
) -> None:
    data = base_config()
    arm = {"motors": "m1", "tip": [0, 0, 1]}
    data["kinematics"] = {"model": "arm.urdf", "chains": {"arm": arm}}
    config = RobotConfig.from_dict(data)
    assert config.kinematics is not None
    spec = kinematics_spec(config.kinematics)
    assert spec.chains[0].motors == ("m1",) and spec.chains[0].tip == (0.0, 0.0, 1.0)
    assert config.to_dict()["kinematics"]["chains"]["arm"]["tip"] == [0.0, 0.0, 1.0]


def test_checks_across_fields_all_report(base_config: Callable[[], Data]) -> None:
    data = base_config()
    data["motors"]["m2"]["id"] = 1
    data["motorgroups"]["loop"] = ["loop"]
    data["controllers"]["lower"]["attached_motors"] = ["m3", "m1"]
    with pytest.raises(ConfigError) as info:
        RobotConfig.from_dict(data, source="robot.yaml")
    fields = [p.field for p in info.value.problems]
    assert fields == ["motorgroups.loop", "motors.m2.id", "controllers.lower.attached_motors[1]"]


def test_a_long_chain_of_groups_is_checked_without_recursion(
    base_config: Callable[[], Data],
) -> None:
    data = base_config()
    count = 5000
    data["motorgroups"].update({f"g{i}": [f"g{i + 1}"] for i in range(count)})
    data["motorgroups"][f"g{count}"] = ["m1", "g0"]
    with pytest.raises(ConfigError, match="cyclic groups"):
        RobotConfig.from_dict(data, source="robot.yaml")
    data["motorgroups"][f"g{count}"] = ["m1"]
    config = RobotConfig.from_dict(data, source="robot.yaml")
    assert config.resolve_group("g0") == ["m1"]
