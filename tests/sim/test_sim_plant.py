"""The MuJoCo plant: registers drive the physics, the physics fills the control tables."""

from __future__ import annotations

import numpy as np
import pytest
from sim_helpers import World

from poppy_core.errors import ConfigError
from poppy_core.robot.frames import to_motor, to_user


def _user_joint(world: World, name: str) -> float:
    """The joint's angle seen in poppy's (user) frame."""
    entry = world.entries[name]
    return to_user(world.sim.joint_deg(name), entry.orientation, entry.offset)


def test_motor_tables_start_at_the_model_pose(torso: World) -> None:
    for name, motor in torso.motors.items():
        assert torso.present_user_deg(name) == pytest.approx(0.0, abs=0.2)
        assert motor.goal_position_deg == pytest.approx(motor.present_position_deg, abs=0.2)


@pytest.mark.parametrize(
    ("name", "target"),
    [
        ("l_shoulder_y", 30.0),
        ("r_shoulder_x", -30.0),
        ("r_elbow_y", 30.0),
        ("l_elbow_y", -30.0),
        ("head_y", 5.0),
        ("bust_x", -5.0),
        ("bust_y", 15.0),
        ("abs_z", 30.0),
    ],
)
def test_the_joint_takes_the_motor_angle(torso: World, name: str, target: float) -> None:
    """Motors of each kind (direct/indirect, with and without offset): the joint turns to the
    motor's own angle, which the motor reads back."""
    for other in torso.motors:
        torso.command(other, 0.0)
    torso.command(name, target)
    torso.run(1.5)
    entry = torso.entries[name]
    motor_deg = to_motor(target, entry.orientation, entry.offset)
    assert torso.sim.joint_deg(name) == pytest.approx(motor_deg, abs=3.0)
    assert torso.motors[name].present_position_deg == pytest.approx(
        torso.sim.joint_deg(name), abs=0.5
    )
    assert torso.present_user_deg(name) == pytest.approx(target, abs=3.0)


FORWARD = -90.0  # l_shoulder_y: the arm raised forward, horizontal


def _arm_forward(world: World, torque: bool) -> None:
    for name in world.motors:
        world.command(name, 0.0)
    entry = world.entries["l_shoulder_y"]
    world.motors["l_shoulder_y"].move_by_hand(to_motor(FORWARD, entry.orientation, entry.offset))
    world.command("l_shoulder_y", FORWARD, torque=torque)


def test_compliant_arm_falls_and_stiff_arm_holds(torso: World) -> None:
    _arm_forward(torso, torque=True)
    torso.run(1.0)
    assert _user_joint(torso, "l_shoulder_y") == pytest.approx(FORWARD, abs=6.0)
    torso.command("l_shoulder_y", FORWARD, torque=False)
    torso.run(1.0)
    assert _user_joint(torso, "l_shoulder_y") > -45.0  # fell toward hanging (0°)


def test_present_load_rises_against_gravity(torso: World) -> None:
    for name in torso.motors:
        torso.command(name, 0.0)
    torso.run(0.5)
    hanging = abs(torso.motors["l_shoulder_y"].table.get_si("present_load") or 0.0)
    _arm_forward(torso, torque=True)
    torso.run(1.0)
    holding = abs(torso.motors["l_shoulder_y"].table.get_si("present_load") or 0.0)
    assert hanging < 3.0
    assert holding > 8.0


def test_torque_limit_lowers_the_force(torso: World) -> None:
    _arm_forward(torso, torque=True)
    torso.run(1.0)
    full = abs(torso.motors["l_shoulder_y"].table.get_si("present_load") or 0.0)
    torso.motors["l_shoulder_y"].table.set_si("torque_limit", 5.0)
    torso.run(1.0)
    limited = abs(torso.motors["l_shoulder_y"].table.get_si("present_load") or 0.0)
    assert limited <= 5.5 < full
    assert _user_joint(torso, "l_shoulder_y") > -60.0  # 5 % cannot hold the arm up


def test_moving_speed_limits_the_motion(ergo: World) -> None:
    for name in ergo.motors:
        ergo.command(name, 0.0)
    ergo.motors["m1"].table.set_si("moving_speed", 30.0)
    ergo.command("m1", 90.0)
    ergo.run(1.0)
    assert 20.0 < abs(ergo.sim.joint_deg("m1")) < 40.0
    assert ergo.motors["m1"].table.get("moving") == 1
    ergo.run(3.0)
    assert ergo.sim.joint_deg("m1") == pytest.approx(90.0, abs=2.0)
    assert ergo.motors["m1"].table.get("moving") == 0


def test_move_by_hand_sets_the_joint(ergo: World) -> None:
    ergo.motors["m3"].move_by_hand(-40.0)  # the motor's own angle; m3 is indirect
    assert ergo.sim.joint_deg("m3") == pytest.approx(-40.0, abs=0.1)
    assert ergo.present_user_deg("m3") == pytest.approx(40.0, abs=0.3)  # one XL-320 step


def test_reset_returns_to_the_initial_pose(torso: World) -> None:
    for name in torso.motors:
        torso.command(name, 0.0)
    torso.run(0.5)
    start = {n: torso.sim.get_object_position(n) for n in ("head", "l_forearm")}
    torso.command("abs_z", 40.0)
    torso.command("l_elbow_y", -40.0)
    torso.run(1.5)
    assert torso.sim.get_object_position("l_forearm") != pytest.approx(start["l_forearm"], abs=0.02)
    torso.sim.reset()
    torso.run(0.5)
    for name, position in start.items():
        assert torso.sim.get_object_position(name) == pytest.approx(position, abs=0.01)
    assert torso.present_user_deg("abs_z") == pytest.approx(0.0, abs=1.0)


def test_added_cube_falls_and_is_tracked(ergo: World) -> None:
    ergo.sim.add_object("cube", "cube", (0.15, 0.0, 0.4), size=0.015, mass=0.02)
    assert ergo.sim.get_object_position("cube")[2] == pytest.approx(0.4)
    ergo.run(1.0)
    x, y, z = ergo.sim.get_object_position("cube")
    assert z == pytest.approx(0.05 + 0.015, abs=0.003)  # resting on the table top
    assert (x, y) == pytest.approx((0.15, 0.0), abs=0.01)
    assert ergo.sim.colliding("cube", "world")
    assert not ergo.sim.colliding("cube", "tip")
    relative = ergo.sim.get_object_position("cube", relative_to="base_link")
    assert relative[2] < 0.0
    assert len(ergo.sim.get_object_orientation("cube")) == 4


def test_objects_keep_the_robot_state_and_names_are_checked(ergo: World) -> None:
    ergo.command("m1", 45.0)
    ergo.run(1.0)
    ergo.sim.add_object("sphere", "ball", (0.1, 0.1, 0.3))
    assert ergo.sim.joint_deg("m1") == pytest.approx(45.0, abs=2.0)
    ergo.run(0.5)
    assert ergo.sim.joint_deg("m1") == pytest.approx(45.0, abs=2.0)
    with pytest.raises(ConfigError):
        ergo.sim.add_object("sphere", "ball", (0.0, 0.0, 0.5))
    with pytest.raises(ConfigError):
        ergo.sim.add_object("pyramid", "c", (0.0, 0.0, 0.5))  # a cone is a kind now
    with pytest.raises(ConfigError):
        ergo.sim.get_object_position("nothing")


def test_render_gives_a_non_blank_image(ergo: World) -> None:
    try:
        image = ergo.sim.render(width=160, height=120)
    except ConfigError as exc:
        pytest.skip(f"no OpenGL backend for offscreen rendering: {exc}")
    assert image.shape == (120, 160, 3)
    assert float(np.std(image)) > 5.0
    framed = ergo.sim.render(camera="front", width=64, height=48)
    assert framed.shape == (48, 64, 3)


def test_a_hand_holds_a_compliant_joint_and_not_a_stiff_one(ergo: World) -> None:
    """The emulator's hand on MuJoCo: a compliant joint goes where the hand holds it; a stiff
    one is left to the physics (no force is applied for the hand, see docs/emulator.md)."""
    ergo.command("m1", 0.0, torque=False)
    ergo.command("m2", 0.0)
    ergo.run(0.3)
    ergo.motors["m1"].hold_by_hand(30.0)
    ergo.motors["m2"].hold_by_hand(30.0)
    ergo.run(0.5)
    assert ergo.sim.joint_deg("m1") == pytest.approx(30.0, abs=1.0)
    assert ergo.sim.joint_deg("m2") == pytest.approx(0.0, abs=3.0)
