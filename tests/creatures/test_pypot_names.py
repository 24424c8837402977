"""pypot's names beside the documentation's examples: factories, moves, servers, refusals."""

from __future__ import annotations

import io
import json
from collections.abc import Iterator
from contextlib import closing
from pathlib import Path

import httpx
import numpy as np
import pytest

from poppy_core import from_config
from poppy_core.errors import ArgumentError, ConfigError, RegisterError
from poppy_core.motion import Move, MovePlayer, MoveRecorder
from poppy_core.pypot import PoppyErgoJr, from_json
from poppy_core.robot import Robot, from_remote, load_profile
from tests.creatures.helpers import wait_until
from tests.helpers.waiting import http_timeout


@pytest.fixture(scope="module")
def ergo() -> Iterator[Robot]:
    """One virtual Ergo Jr built as pypot users build it."""
    with PoppyErgoJr(simulator="dummy") as robot:
        yield robot


def test_to_config_then_from_json_as_the_documentation(ergo: Robot, tmp_path: Path) -> None:
    # Lines 3000 and 3012-3115: save the config, build a robot from it in a closing block.
    config = ergo.to_config()
    with open(tmp_path / "myconfig.json", "w") as f:
        json.dump(config, f, indent=2)
    with closing(from_json(tmp_path / "myconfig.json", use_dummy_io=True)) as my_robot:
        assert [m.name for m in my_robot.motors] == [m.name for m in ergo.motors]
        assert my_robot.alias == ergo.alias
    assert my_robot.closed
    with pytest.raises(ArgumentError, match="from_config"):
        from_json(config)  # type: ignore[arg-type]


def test_from_remote_drives_the_served_robot() -> None:
    with PoppyErgoJr(simulator="dummy", use_http=True, http_port=0) as robot:
        remote = from_remote("127.0.0.1", robot.http.port)
        try:
            assert [m.name for m in remote.motors] == [m.name for m in robot.motors]
            robot.m1.compliant = False
            remote.m1.goal_position = 15
            assert wait_until(lambda: abs(robot.m1.goal_position - 15) < 0.5, 10.0)
        finally:
            remote.close()


def test_move_built_by_hand_saves_and_loads_as_pypot_json() -> None:
    move = Move(10.0)
    for i in range(5):
        move.add_position({"m1": [float(i), 0.0], "m2": [-float(i), 0.0]}, i / 10.0)
    timed = move.positions()
    assert list(timed) == pytest.approx([0.0, 0.1, 0.2, 0.3, 0.4])
    assert timed[0.2] == {"m1": [2.0, 0.0], "m2": [-2.0, 0.0]}
    assert np.array_equal(move.positions[:, 0], [0, 1, 2, 3, 4])  # still the array
    text = io.StringIO()
    move.save(text)
    document = json.loads(text.getvalue())
    assert document["framerate"] == 10.0 and len(document["positions"]) == 5
    again = Move.load(io.StringIO(text.getvalue()))
    assert again.same_as(move) and Move.loads(text.getvalue()).same_as(move)
    with pytest.raises(ArgumentError, match="motors"):
        move.add_position({"m3": 0.0}, 0.5)
    with pytest.raises(ArgumentError, match="before the last"):
        move.add_position({"m1": 0.0, "m2": 0.0}, 0.1)


def test_recorder_and_player_with_pypot_arguments(ergo: Robot, tmp_path: Path) -> None:
    recorder = MoveRecorder(ergo, 20, ["m1"])
    recorder.add_tracked_motors(["m2"])
    assert [m.name for m in recorder.tracked_motors] == ["m1", "m2"]
    recorder.start()
    assert wait_until(lambda: recorder.frames_recorded >= 3, 10.0)
    with pytest.raises(ArgumentError, match="before start"):
        recorder.add_tracked_motors(["m3"])
    recorder.stop()
    assert not recorder.is_alive()
    move = Move(10.0)
    for i in range(6):
        move.add_position({"m1": 4.0 * i, "m2": 0.0})
    path = tmp_path / "wave.json"
    with open(path, "w") as f:
        move.save(f)
    ergo.compliant = False
    player = MovePlayer(ergo, move_filename=str(path), play_speed=-2.0, start_max_speed=200)
    assert player.backwards and player.speed == 2.0
    assert player.duration() == pytest.approx(move.duration_s / 2)
    player.start()
    assert player.wait_to_stop(30.0) and not player.is_alive()
    assert ergo.m1.goal_position == pytest.approx(0.0, abs=0.5)  # backwards: ends on frame 0
    with pytest.raises(ArgumentError, match="move_filename"):
        MovePlayer(ergo)


def test_groups_act_on_their_motors(ergo: Robot) -> None:
    base = ergo.base
    base.compliant = False
    assert not base.compliant and not ergo.m1.compliant
    base.compliant = True
    assert base.compliant and ergo.m3.compliant
    base.compliant = False
    base.moving_speed = 80
    assert all(m.moving_speed == pytest.approx(80, abs=1) for m in base)
    base.goto_position(10.0, 0.3, wait=True)
    assert all(m.goal_position == pytest.approx(10.0, abs=0.5) for m in base)
    base.goto_position({"m1": -5.0}, 0.2, control="dummy", wait=True)
    assert ergo.m1.goal_position == pytest.approx(-5.0, abs=0.5)
    with pytest.raises(ArgumentError, match="3 motors"):
        base.goto_position([1.0, 2.0], 0.2)
    with pytest.raises(AttributeError, match="sets only"):
        base.colour = "red"  # type: ignore[attr-defined]


def test_motor_names_of_pypot(ergo: Robot) -> None:
    m = ergo.m6
    assert f"{m.model}" == "XL-320" and str(m.model) == "XL-320"
    assert (m.lower_limit, m.upper_limit) == m.angle_limit
    assert m.control_mode == "joint"
    assert {"lower_limit", "upper_limit", "control_mode", "registers"} <= set(m.registers)
    m.safe_compliant = True
    assert m.compliant_behavior == "safe"
    m.compliant_behavior("dummy")
    assert not m.safe_compliant
    with pytest.raises(RegisterError, match="goto_behavior"):
        m.goto_behavior = "linear"


def test_use_snap_serves_the_snap_routes_until_close() -> None:
    robot = PoppyErgoJr(simulator="dummy", use_snap=True, snap_port=0)
    try:
        url = robot.snap.url
        answer = httpx.get(f"{url}/motors/motors", timeout=http_timeout(10))
        assert answer.text == "m1/m2/m3/m4/m5/m6"
    finally:
        robot.close()
    with pytest.raises(httpx.TransportError):
        httpx.get(f"{url}/motors/motors", timeout=http_timeout(2))


def test_refused_pypot_options_name_what_to_do() -> None:
    with pytest.raises(ConfigError, match=r"V-REP scene: MuJoCo reads an MJCF file"):
        PoppyErgoJr(simulator="mujoco", scene="poppy_ergo_jr.ttt")
    with pytest.raises(ConfigError, match="need simulator='mujoco'"):
        PoppyErgoJr(simulator="dummy", scene="scene.xml")
    with pytest.raises(ConfigError, match="serial port"):
        PoppyErgoJr(simulator="dummy", port=19997)
    with pytest.raises(ConfigError, match="'mujoco'"):
        PoppyErgoJr(simulator="gazebo")


def test_simulated_creatures_hold_their_start_pose_as_pypot_simulators() -> None:
    # pypot's V-REP and dummy robots follow goals from the start: the documentation's
    # simulation quickstart sets goal_position without turning compliance off.
    with PoppyErgoJr(simulator="dummy") as robot:
        assert not robot.compliant
        robot.m1.goal_position = 20
        assert wait_until(lambda: abs(robot.m1.present_position - 20) < 1.5, 10.0)
        with pytest.raises(ConfigError, match="simulator='mujoco'"):
            robot.reset_simulation()
        with pytest.raises(ConfigError, match="simulator='mujoco'"):
            robot.get_object_position("head")
        # each V-REP call names itself: pypot's property, not the method behind it
        with pytest.raises(ConfigError, match=r"^current_simulation_time\(\) needs"):
            robot.current_simulation_time  # noqa: B018 (the read is the call)
        with pytest.raises(ConfigError, match=r"^add_cube\(\) needs"):
            robot.add_cube("box", [0, 0, 0.1], [0.02, 0.02, 0.02], 0.01)
        with pytest.raises(ConfigError, match=r"^track_objects\(\) needs"):
            robot.track_objects(["head"])


def test_a_pypot_config_dict_finds_its_simulation_model() -> None:
    pytest.importorskip("mujoco")
    my_config = load_profile("ergo-jr").to_pypot_dict()  # no profile header: motor names only
    with from_config(my_config, sim="mujoco") as robot:
        assert robot.simulation is not None
        assert "head_follow" in robot.primitive_names  # recognised as a simulated Ergo Jr
        robot.simulation.stop()  # the compliant arm may sag: compare one frozen world
        # V-REP's "<link>_visual" names read as the link
        assert robot.get_object_position("tip_visual") == robot.simulation.get_object_position(
            "tip"
        )
