"""Every error a user can reach is a typed PoppyError; a closed robot says so; configs as dicts."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from poppy_core import from_config, from_profile
from poppy_core.errors import (
    ArgumentError,
    ConfigError,
    PoppyError,
    RobotClosedError,
    UnknownMotorError,
)
from poppy_core.motion import MovePlayer, PositionWatcher, Sinus, Square
from poppy_core.motion.move import Move
from poppy_core.robot import Robot, RobotConfig, load_profile
from tests.helpers.fixtures import ergo_fixture

ergo = ergo_fixture(scope="module")


# -- item 6: from_config(dict) and json.dumps(robot.to_config()) ---------------------------------


def test_public_config_round_trips_through_a_dict_and_json(
    public_config: tuple[Path, dict[str, Any]],
) -> None:
    _, data = public_config
    with from_config(data, sim=True, start_sync=False) as robot:
        text = json.dumps(robot.to_config(), indent=2)
    again = json.loads(text)
    assert set(again["motors"]) == set(data["motors"])
    for motor, entry in data["motors"].items():
        assert again["motors"][motor]["id"] == entry["id"]
        assert again["motors"][motor]["angle_limit"] == pytest.approx(entry["angle_limit"])
    assert again["controllers"].keys() == data["controllers"].keys()
    with from_config(again, sim=True, start_sync=False) as robot:
        assert json.loads(json.dumps(robot.to_config())) == again


@pytest.mark.parametrize("profile", ["ergo-jr", "torso", "humanoid"])
def test_profiles_round_trip_through_json(profile: str) -> None:
    with from_profile(profile, sim=True, start_sync=False) as robot:
        config = robot.to_config()
        text = json.dumps(config)
    again = RobotConfig.from_dict(json.loads(text))
    assert again.motors.keys() == load_profile(profile).motors.keys()


def test_from_config_refuses_other_objects_with_a_config_error() -> None:
    with pytest.raises(ConfigError, match="a RobotConfig, a mapping or a file path"):
        from_config(42, sim=True)  # type: ignore[arg-type]


def test_to_config_reflects_the_motors(ergo: Robot) -> None:
    ergo.m1.angle_limit = (-100, 100)
    try:
        assert ergo.to_config()["motors"]["m1"]["angle_limit"] == pytest.approx([-100, 100])
        assert ergo.to_robot_config().motors["m1"].angle_limit == pytest.approx((-100, 100))
    finally:
        ergo.m1.angle_limit = (-90, 90)


# -- item 8: motor lists of primitives --------------------------------------------------------


def test_a_motor_name_alone_is_a_list_of_one(ergo: Robot) -> None:
    sinus = Sinus(ergo, 50, "m2", amp=5)
    assert sinus.motor_list == ["m2"]
    assert PositionWatcher(ergo, 10, "m3").watched_motors == ["m3"]


def test_a_group_name_is_its_motors(ergo: Robot) -> None:
    group = next(iter(ergo.motorgroups))
    assert Square(ergo, 50, group).motor_list == [m.name for m in ergo.motorgroups[group]]


@pytest.mark.parametrize("motors", ["head_z", ["m1", "head_z"], ("m1", 3)])
def test_unknown_motors_are_refused_when_the_primitive_is_built(ergo: Robot, motors: Any) -> None:
    with pytest.raises(PoppyError) as caught:
        Sinus(ergo, 50, motors)
    message = str(caught.value)
    assert "m1, m2, m3" in message  # the known motors
    if isinstance(caught.value, UnknownMotorError):
        assert caught.value.motor in ("head_z", "3")
        assert "head_z" in message or "3" in message


def test_setting_an_unknown_motor_list_is_refused(ergo: Robot) -> None:
    sinus = Sinus(ergo, 50, ["m1"])
    with pytest.raises(ConfigError, match="head_z"):
        sinus.set_property("motor_list", "m1,head_z")
    assert sinus.motor_list == ["m1"]


# -- item 9: typed errors --------------------------------------------------------------------


def test_gotos_refuse_bad_arguments_with_argument_errors(ergo: Robot) -> None:
    with pytest.raises(ArgumentError) as caught:
        ergo.goto_position({"m1": 10}, -1)
    assert isinstance(caught.value, ValueError)  # old `except ValueError` still works
    with pytest.raises(ArgumentError, match="control"):
        ergo.m1.goto_position(10, 1, control="fast")
    with pytest.raises(ArgumentError, match="duration"):
        ergo.goto_position({"m1": 10}, float("nan"))


def test_unknown_motor_names_a_motor_and_the_known_ones(ergo: Robot) -> None:
    with pytest.raises(UnknownMotorError) as caught:
        ergo.motor("head_z")
    assert caught.value.motor == "head_z"
    assert caught.value.known == [m.name for m in ergo.motors]
    with pytest.raises(UnknownMotorError):
        ergo.goto_position({"head_z": 3}, 1)


@pytest.mark.parametrize(
    ("primitive", "prop", "value"),
    [
        ("dance", "tempo_scale", -1.0),
        ("safe_power_up", "torque_limit", 150.0),
        ("safe_power_up", "control", "fast"),
        ("jump", "jumps", -2),
        ("sinus", "update_freq", 0.0),
        ("square", "duty", 2.0),
    ],
)
def test_creature_and_builtin_properties_refuse_bad_values_with_poppy_errors(
    ergo: Robot, primitive: str, prop: str, value: Any
) -> None:
    from poppy_core.motion import attach_builtins

    attach_builtins(ergo)
    target = getattr(ergo, primitive)
    with pytest.raises(ArgumentError) as caught:
        setattr(target, prop, value)
    assert caught.value.field == prop


def test_player_refuses_bad_arguments_with_argument_errors(ergo: Robot) -> None:
    move = Move(50, ["m1"], [[0.0], [1.0]])
    with pytest.raises(ArgumentError):
        MovePlayer(ergo, move, speed=0)
    with pytest.raises(ArgumentError):
        MovePlayer(ergo, move, loops=0)
    with pytest.raises(ArgumentError):
        MovePlayer(ergo, Move(50, ["m1"], []))


def test_moves_refuse_bad_values_with_argument_errors() -> None:
    with pytest.raises(ArgumentError):
        Move(0, ["m1"], [[0.0]])
    with pytest.raises(ArgumentError):
        Move(50, ["m1", "m1"], [[0.0, 0.0]])


def test_a_closed_robot_raises_robot_closed_error(tmp_path: Path) -> None:
    robot = from_profile("ergo-jr", sim=True)
    sinus = Sinus(robot, 50, ["m1"])
    robot.close()
    with pytest.raises(RobotClosedError):
        robot.goto_position({"m1": 10}, 1)
    with pytest.raises(RobotClosedError):
        robot.m1.goto_position(10, 1)
    with pytest.raises(RobotClosedError):
        sinus.start()
    with pytest.raises(RobotClosedError):
        robot.m1.goal_position = 10
    with pytest.raises(RobotClosedError):
        robot.m1.compliant = True
    assert isinstance(robot.m1.present_position, float)  # reads still give the last values


def test_register_errors_name_the_motor(ergo: Robot) -> None:
    from poppy_core.errors import RegisterError

    with pytest.raises(RegisterError) as caught:
        ergo.m2.moving_speed = -1
    assert (caught.value.motor, caught.value.register) == ("m2", "moving_speed")
    with pytest.raises(RegisterError) as caught:
        ergo.m3.torque_limit = 150  # out of the register's range: found by the model
    assert (caught.value.motor, caught.value.register) == ("m3", "torque_limit")
    assert str(caught.value).startswith("m3: ")
    sinus = Sinus(ergo, 50, ["m1"])
    with pytest.raises(RegisterError) as caught:
        sinus.robot.motor("m1").goal_position = "far"
    assert (caught.value.motor, caught.value.register) == ("m1", "goal_position")
