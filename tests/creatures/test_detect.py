"""Which creature a config describes, and attaching creatures by name."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from poppy_core import from_config
from poppy_core.creatures import CREATURES, attach_creature, detect_kind, normalize_kind
from poppy_core.errors import ConfigError
from poppy_core.robot import RobotConfig, load_profile
from tests.helpers.pypot_names import UPPER_BODY_PRIMITIVES

# Copies of the public pypot configs (no profile header), kept by the robot tests.
PYPOT_DATA = Path(__file__).parents[1] / "robot" / "data"


@pytest.mark.parametrize("kind", ["ergo-jr", "torso", "humanoid"])
def test_profiles_name_their_creature(kind: str) -> None:
    assert detect_kind(load_profile(kind)) == kind


@pytest.mark.parametrize(
    ("file", "kind"),
    [("poppy_ergo_jr", "ergo-jr"), ("poppy_torso", "torso"), ("poppy_humanoid", "humanoid")],
)
def test_pypot_configs_are_recognised_by_their_motor_names(file: str, kind: str) -> None:
    data = json.loads((PYPOT_DATA / f"{file}.json").read_text(encoding="utf-8"))
    config = RobotConfig.from_dict(data)
    assert config.profile is None
    assert detect_kind(config) == kind


def _two_motors(header: dict[str, str] | None = None) -> RobotConfig:
    data: dict[str, Any] = {
        "controllers": {"c": {"port": "auto", "protocol": 2, "attached_motors": ["a", "b"]}},
        "motors": {
            "a": {"id": 1, "type": "XL-320", "angle_limit": [-90, 90]},
            "b": {"id": 2, "type": "XL-320", "angle_limit": [-90, 90]},
        },
    }
    if header is not None:
        data["profile"] = header
    return RobotConfig.from_dict(data)


def test_other_robots_are_no_creature() -> None:
    assert detect_kind(_two_motors()) is None
    assert detect_kind(_two_motors({"name": "my-arm", "kind": "gripper"})) is None
    # A header whose kind is empty but whose name is a creature's still counts.
    assert detect_kind(_two_motors({"name": "poppy-torso"})) == "torso"


def test_ergo_jr_motor_names_with_one_missing_is_no_creature() -> None:
    config = load_profile("ergo-jr").to_pypot_dict()
    del config["motors"]["m6"]
    config["motorgroups"]["tip"].remove("m6")
    assert detect_kind(RobotConfig.from_dict(config)) is None


@pytest.mark.parametrize(
    ("spelling", "kind"),
    [
        ("PoppyErgoJr", "ergo-jr"),
        ("ergo_jr", "ergo-jr"),
        ("Poppy Humanoid", "humanoid"),
        ("TORSO", "torso"),
        ("poppy-torso", "torso"),
        ("spider", None),
    ],
)
def test_normalize_kind(spelling: str, kind: str | None) -> None:
    assert normalize_kind(spelling) == kind


def test_a_plain_robot_gets_no_behaviour_and_a_named_one_can_be_attached() -> None:
    with from_config(_two_motors(), sim=True) as robot:
        assert robot.primitive_names == []
        assert "creature" not in robot.extensions
        with pytest.raises(ConfigError, match="unknown creature 'spider'"):
            attach_creature(robot, "spider")


def test_every_creature_declares_its_primitives() -> None:
    assert set(CREATURES) == {"ergo-jr", "torso", "humanoid"}
    assert {
        "base_posture",
        "rest_posture",
        "curious_posture",
        "tetris_posture",
        "safe_power_up",
        "dance",
        "jump",
        "tinsel_demo",
        "stubborn_demo",
        "chicken_demo",
        "puzzel_demo",
    } == set(CREATURES["ergo-jr"].primitives)
    upper = set(UPPER_BODY_PRIMITIVES)
    assert set(CREATURES["torso"].primitives) == upper | {"init_position"}
    assert set(CREATURES["humanoid"].primitives) == upper | {"stand_position", "sit_position"}
