"""pypot's V-REP calls (reference lines 3483-3515, 7061-7283) on simulator='mujoco': each call
form of the documentation, as it is written there, on a MuJoCo Ergo Jr."""

from __future__ import annotations

import math
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from poppy_core.errors import ArgumentError, ConfigError
from tests.helpers.waiting import eventually

pytest.importorskip("mujoco")

ROOT = Path(__file__).resolve().parents[2]
TABLE_TOP_M = 0.05


@pytest.fixture(scope="module")
def poppy() -> Iterator[Any]:
    from poppy_core.pypot import PoppyErgoJr

    robot = PoppyErgoJr(simulator="mujoco")
    yield robot
    robot.close()


def _resting_on_the_table(robot: Any, name: str, half_height: float) -> bool:
    z = robot.get_object_position(name)[2]
    return abs(z - (TABLE_TOP_M + half_height)) < 0.004


def test_add_cube_name_position_sizes_mass(poppy: Any) -> None:
    # add_cube(name, position, sizes, mass): sizes are the box's sides (V-REP's full extents)
    poppy.add_cube("cube", [0.15, 0.1, 0.2], [0.04, 0.04, 0.04], 0.05)
    assert eventually(lambda: _resting_on_the_table(poppy, "cube", 0.02), timeout_s=20)
    model = poppy.simulation.model
    import mujoco

    geom = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, "cube")
    assert [round(float(v), 4) for v in model.geom_size[geom]] == [0.02, 0.02, 0.02]
    assert math.isclose(float(model.body_mass[model.geom_bodyid[geom]]), 0.05)


def test_add_sphere_with_precision(poppy: Any) -> None:
    # add_sphere(name, position, sizes, mass, precision=[10, 10]): sizes[0] the diameter
    poppy.add_sphere("ball", [0.15, -0.15, 0.2], [0.03, 0.03, 0.03], 0.02, precision=[10, 10])
    assert eventually(lambda: _resting_on_the_table(poppy, "ball", 0.015), timeout_s=20)


def test_add_cylinder_with_precision(poppy: Any) -> None:
    # add_cylinder(name, position, sizes, mass, precision=[10, 10]): diameter, _, height
    poppy.add_cylinder("can", [-0.15, 0.15, 0.2], [0.03, 0.03, 0.06], 0.03, precision=[10, 10])
    assert eventually(lambda: _resting_on_the_table(poppy, "can", 0.03), timeout_s=20)


def test_add_cone_with_precision(poppy: Any) -> None:
    # add_cone(name, position, sizes, mass, precision=[10, 10]): base diameter, _, height
    poppy.add_cone("cone", [-0.15, -0.15, 0.2], [0.04, 0.04, 0.05], 0.03, precision=[10, 10])
    assert eventually(lambda: _resting_on_the_table(poppy, "cone", 0.025), timeout_s=20)


def test_add_shapes_refuse_bad_sizes_and_masses(poppy: Any) -> None:
    with pytest.raises(ArgumentError, match="sizes"):
        poppy.add_cube("flat", [0.1, 0.1, 0.2], [0.04, 0.0, 0.04], 0.05)
    with pytest.raises(ConfigError, match="3 numbers"):
        poppy.add_sphere("odd", [0.1, 0.1, 0.2], [0.03], 0.05)
    with pytest.raises(ArgumentError, match="mass"):
        poppy.add_cylinder("light", [0.1, 0.1, 0.2], [0.03, 0.03, 0.05], -1)


def test_set_object_position_then_get_object_position(poppy: Any) -> None:
    # set_object_position(object_name, position=[0, 0, 0]); get_object_position(object_name)
    poppy.add_cube("block", [0.2, -0.2, 0.2], [0.02, 0.02, 0.02], 0.01)
    poppy.set_object_position("block", position=[0.25, -0.25, 0.3])
    x, y, z = poppy.get_object_position("block")
    assert (round(x, 3), round(y, 3)) == (0.25, -0.25) and 0.0 < z <= 0.3
    assert eventually(lambda: _resting_on_the_table(poppy, "block", 0.01), timeout_s=20)
    with pytest.raises(ConfigError, match="moves with the robot's joints"):
        poppy.set_object_position("tip", [0.0, 0.0, 0.3])


def test_get_object_position_relative_to_object(poppy: Any) -> None:
    # get_object_position(object_name, relative_to_object=None), V-REP's `<link>_visual` names
    tip = poppy.get_object_position("tip_visual")
    base = poppy.get_object_position("base_link")
    relative = poppy.get_object_position("tip", relative_to_object="base_link")
    # the base link is not turned: the offset is the difference of the world positions
    assert all(abs(r - (t - b)) < 1e-6 for r, t, b in zip(relative, tip, base, strict=True))


def test_set_object_orientation_then_get_object_orientation(poppy: Any) -> None:
    # get_object_orientation(object_name, relative_to_object=None): V-REP's Euler angles (rad)
    poppy.add_cube("tile", [-0.25, 0.25, 0.3], [0.05, 0.05, 0.01], 0.01)
    poppy.set_object_orientation("tile", [0.0, 0.0, math.pi / 4])
    alpha, beta, gamma = poppy.get_object_orientation("tile")
    assert abs(alpha) < 0.05 and abs(beta) < 0.05 and abs(gamma - math.pi / 4) < 0.05
    # as V-REP's: alpha about x, then beta about the new y, then gamma about the new z
    poppy.set_object_orientation("tile", [0.3, -0.2, 0.5])
    assert [round(a, 4) for a in poppy.get_object_orientation("tile")] == [0.3, -0.2, 0.5]
    link = poppy.get_object_orientation("tip", relative_to_object="tip")
    assert all(abs(a) < 1e-9 for a in link)


def test_get_simulation_current_time_and_robot_property(poppy: Any) -> None:
    # get_simulation_current_time(timer='CurrentTime'); pypot's robot.current_simulation_time
    start = poppy.get_simulation_current_time(timer="CurrentTime")
    assert start > 0.0
    assert eventually(lambda: poppy.current_simulation_time > start + 0.2, timeout_s=10)


def test_get_collision_state_and_tracked_collisions(poppy: Any) -> None:
    # get_collision_state(collision_name): a body touching another body or the world
    poppy.add_sphere("drop", [0.3, 0.0, 0.25], [0.02, 0.02, 0.02], 0.01)
    poppy.track_collisions(["drop"])
    assert not poppy.get_collision_state("drop") and not poppy.drop.colliding  # falling
    assert eventually(lambda: poppy.get_collision_state("drop"), timeout_s=20)
    assert poppy.drop.colliding


def test_tracked_objects_give_position_and_orientation(poppy: Any) -> None:
    poppy.track_objects(["ball"])
    # the physics runs between the two reads: the ball may still be settling
    assert poppy.ball.position == pytest.approx(poppy.get_object_position("ball"), abs=1e-4)
    assert poppy.ball.orientation == pytest.approx(poppy.get_object_orientation("ball"), abs=1e-3)
    with pytest.raises(ConfigError, match="already"):
        poppy.track_objects(["tip"])  # the Ergo Jr's robot.tip is taken


def test_reset_simulation(poppy: Any) -> None:
    poppy.set_object_position("cube", [0.1, 0.25, 0.4])
    poppy.reset_simulation()
    x, y, _ = poppy.get_object_position("cube")
    assert (round(x, 3), round(y, 3)) == (0.15, 0.1)  # back where it was added


SCENE_PROPS = """
    <body name="crate" pos="0.18 0 0.2">
      <freejoint name="crate_free"/>
      <geom class="prop" type="box" size="0.02 0.02 0.02" mass="0.05" rgba="0.8 0.2 0.2 1"/>
    </body>
"""


def _scene(folder: Path) -> Path:
    """A user's scene: a copy of the Ergo Jr's model with a crate."""
    model = (ROOT / "profiles" / "ergo-jr" / "model.xml").read_text(encoding="utf-8")
    path = folder / "my_scene.xml"
    path.write_text(model.replace("  </worldbody>", SCENE_PROPS + "  </worldbody>", 1))
    return path


def test_load_scene_scene_path(tmp_path: Path) -> None:
    # load_scene(scene_path, start=False) on a robot built without a scene
    from poppy_core.pypot import PoppyErgoJr

    robot = PoppyErgoJr(simulator="mujoco")
    try:
        robot.load_scene(_scene(tmp_path), start=False)
        assert "crate" in robot.simulation.body_names()
        assert eventually(lambda: _resting_on_the_table(robot, "crate", 0.02), timeout_s=20)
        robot.m1.goal_position = 30  # the motors still drive the scene's joints
        assert eventually(lambda: abs(robot.m1.present_position - 30) < 3, timeout_s=20)
    finally:
        robot.close()


def test_creature_scene_and_tracked_objects(tmp_path: Path) -> None:
    # from_vrep(config, ..., scene, tracked_objects=[...], tracked_collisions=[...]), as the
    # creature's arguments: PoppyErgoJr(simulator='mujoco', scene=...)
    from poppy_core.pypot import PoppyErgoJr

    robot = PoppyErgoJr(
        simulator="mujoco",
        scene=str(_scene(tmp_path)),
        tracked_objects=["crate"],
        tracked_collisions=["crate"],
    )
    try:
        assert eventually(lambda: robot.crate.colliding, timeout_s=20)  # it landed
        assert eventually(lambda: abs(robot.crate.position[2] - 0.07) < 0.004, timeout_s=20)
        assert robot.crate.colliding  # resting on the table
    finally:
        robot.close()


def test_a_scene_without_the_robot_is_refused(tmp_path: Path) -> None:
    from poppy_core.pypot import PoppyErgoJr

    empty = tmp_path / "empty.xml"
    empty.write_text("<mujoco><worldbody><geom size='1 1 0.1' type='plane'/></worldbody></mujoco>")
    with pytest.raises(ConfigError, match="no joint/actuator"):
        PoppyErgoJr(simulator="mujoco", scene=str(empty))
    with pytest.raises(ConfigError, match="cannot read"):
        PoppyErgoJr(simulator="mujoco", scene=str(tmp_path / "missing.xml"))
