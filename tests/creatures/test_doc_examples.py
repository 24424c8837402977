"""The documentation's Python examples run on poppy with only the import line changed.

Each runs on a Poppy Torso (the documentation's examples name its head and arms) built by
``PoppyTorso(simulator=...)`` with the ideal servos (``'dummy'``) and with MuJoCo physics, and
asserts what the example is for. The examples' text is in ``doc_examples.py``.
"""

from __future__ import annotations

import ast
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from poppy_core import from_config
from poppy_core.creatures.postures import clamp_to_limits, humanoid_sit
from poppy_core.errors import ConfigError
from poppy_core.motion import LoopPrimitive, Move, PositionWatcher
from poppy_core.pypot import PoppyErgoJr, PoppyTorso
from poppy_core.robot import MotorGroup, Robot, load_profile
from tests.creatures import doc_examples as doc
from tests.creatures.helpers import positions, reached, stop_all, virtual, wait_until
from tests.helpers.pypot_names import TORSO_PRIMITIVES

SIMULATORS = ["dummy", "mujoco"]
TOLERANCE_DEG = {"dummy": 1.5, "mujoco": 4.0}


@pytest.fixture(scope="module", params=SIMULATORS)
def torso(request: pytest.FixtureRequest) -> Iterator[Robot]:
    """A Poppy Torso as the documentation builds one, on each simulator."""
    if request.param == "mujoco":
        pytest.importorskip("mujoco")
    robot = doc.run(doc.CREATE_TORSO, SIMULATOR=request.param)["poppy"]
    robot.extensions["doc_simulator"] = request.param
    yield robot
    robot.close()


@pytest.fixture
def poppy(torso: Robot) -> Robot:
    """The torso, stiff at 0° with no primitive running (the examples start from there)."""
    stop_all(torso)
    for motor in torso.motors:
        motor.compliant = False
    torso.goto_position(dict.fromkeys((m.name for m in torso.motors), 0.0), 0.5, wait=True)
    return torso


def _near(robot: Robot, name: str, target: float) -> bool:
    tolerance = TOLERANCE_DEG[robot.extensions["doc_simulator"]]  # type: ignore[index]
    return abs(robot.motor(name).present_position - target) <= tolerance


def test_listing_motors_prints_each_motor_and_position(
    poppy: Robot, capsys: pytest.CaptureFixture[str]
) -> None:
    doc.run(doc.LIST_MOTORS, poppy=poppy)
    out = capsys.readouterr().out
    assert "head_z" in out and "motor l_shoulder_x in position" in out


def test_groups_are_listed_and_iterated(poppy: Robot, capsys: pytest.CaptureFixture[str]) -> None:
    doc.run(doc.GROUPS, poppy=poppy)
    out = capsys.readouterr().out
    assert "motor group  head" in out and "motor group  torso" in out
    assert "motor head_z in position" in out and "motor head_y in position" in out
    assert isinstance(poppy.head, MotorGroup) and len(poppy.head) == 2


def test_compliance_of_robot_group_and_motor(poppy: Robot) -> None:
    doc.run(doc.COMPLIANCE, poppy=poppy)
    assert not poppy.head_z.compliant and not poppy.head_y.compliant
    assert not poppy.l_shoulder_x.compliant
    assert poppy.r_shoulder_x.compliant and poppy.abs_z.compliant


def test_goal_positions_move_the_head(poppy: Robot) -> None:
    doc.run(doc.GOAL_POSITION, poppy=poppy)
    assert wait_until(lambda: _near(poppy, "head_y", -10.0), 10.0)
    assert _near(poppy, "head_z", 20.0)


def test_moving_speed_then_goal(poppy: Robot) -> None:
    doc.run(doc.MOVING_SPEED, poppy=poppy)
    assert poppy.head_y.moving_speed == pytest.approx(50.0, abs=1.0)
    assert wait_until(lambda: _near(poppy, "head_y", -10.0), 10.0)


def test_goto_with_and_without_wait(poppy: Robot) -> None:
    seen: list[tuple[float, float]] = []  # (goal, present) as each call returned
    original = poppy.head_y.goto_position

    def spy(*args: object, **kwargs: object) -> object:
        handle = original(*args, **kwargs)  # type: ignore[arg-type]
        seen.append((poppy.head_y.goal_position, poppy.head_y.present_position))
        return handle

    poppy.head_y.goto_position = spy  # type: ignore[method-assign]
    try:
        doc.run(doc.GOTO, poppy=poppy)
    finally:
        del poppy.head_y.goto_position
    # wait=True returned once its trajectory had ended: the goal is the target; the position read
    # then may be a sync cycle or two behind it (a busy machine ran one 1.9° behind)
    (goal, present), (_, present_after) = seen
    assert goal == pytest.approx(10.0, abs=0.01)
    assert abs(present - 10.0) <= 5.0
    assert abs(present_after - 10.0) <= 5.0  # wait=False returned before the 2 s motion went far
    assert wait_until(lambda: _near(poppy, "head_y", -10.0), 10.0)


def test_robot_goto_position_with_both_controls(poppy: Robot) -> None:
    doc.run(doc.ROBOT_GOTO, robot=poppy)
    doc.run(doc.ROBOT_GOTO_DUMMY, robot=poppy)
    # wait=True waits the 3 s of the trajectory; a loaded MuJoCo may lag behind the wall clock
    assert wait_until(lambda: _near(poppy, "head_y", 20.0) and _near(poppy, "head_z", 0.0), 10.0)


def test_motor_information_prints_model_names(
    poppy: Robot, capsys: pytest.CaptureFixture[str]
) -> None:
    doc.run(doc.MOTOR_INFO, robot=poppy)
    out = capsys.readouterr().out
    head = poppy.head_z
    assert f"motor  head_z ( {head.model.name} ), id:  {head.id}" in out  # the name, no repr
    assert "ServoModel" not in out
    assert "temperature: " in out and "load: " in out


def test_safe_compliance_called_as_the_documentation_does(poppy: Robot) -> None:
    doc.run(doc.SAFE_COMPLIANCE, robot=poppy)
    assert poppy.head_z.compliant_behavior == "safe" and poppy.head_z.compliant
    doc.run(doc.MAX_TORQUE, robot=poppy)
    assert wait_until(lambda: poppy.head_z.max_torque == pytest.approx(20.0, abs=0.5))


def test_all_motors_to_zero(poppy: Robot, capsys: pytest.CaptureFixture[str]) -> None:
    poppy.head_z.goto_position(30, 0.3, wait=True)
    doc.run(doc.ALL_TO_ZERO, robot=poppy)
    assert wait_until(lambda: _near(poppy, "head_z", 0.0), 10.0)
    assert capsys.readouterr().out.count("position: ") == len(poppy.motors)


def test_goal_speed_loop_turns_the_head(poppy: Robot) -> None:
    start = poppy.head_y.present_position
    doc.run(doc.GOAL_SPEED, robot=poppy)
    assert poppy.head_y.present_position > start + 2.0  # driven toward +20 by speed control


def test_motor_goto_with_both_controls(poppy: Robot) -> None:
    doc.run(doc.MOTOR_GOTO, robot=poppy)
    assert wait_until(lambda: _near(poppy, "head_z", 20.0), 10.0)
    poppy.head_z.goto_position(0, 0.5, wait=True)
    # dummy plans its one speed from the present position (as pypot does): start from rest, or a
    # position read while the head still moves makes that speed too low for the 3 s
    assert wait_until(lambda: _near(poppy, "head_z", 0.0) and abs(poppy.head_z.present_speed) < 2)
    start = time.monotonic()
    doc.run(doc.MOTOR_GOTO_DUMMY, robot=poppy)
    assert time.monotonic() - start >= 3.0 - 0.05  # wait=True: back when the motion is over
    assert wait_until(lambda: _near(poppy, "head_z", 20.0))  # a sync period or so late at most


def test_goto_behavior_honoured_in_both_spellings(poppy: Robot) -> None:
    assert poppy.head_z.goto_behavior == "minjerk"  # the Torso's, as pypot's poppy_torso
    poppy.head_z.goto_behavior = "minijerk"  # the documentation's spelling
    assert poppy.head_z.goto_behavior == "minjerk"
    poppy.head_z.goto_behavior = "dummy"
    try:
        poppy.head_z.goto_position(25, 1.0, wait=True)  # one goal at a constant speed
        assert poppy.head_z.goal_position == pytest.approx(25.0, abs=0.5)
    finally:
        poppy.head_z.goto_behavior = "minjerk"


def test_sinus_on_two_motors_with_pause_and_resume(poppy: Robot) -> None:
    watcher = PositionWatcher(poppy, 25, ["head_z", "head_y"])
    watcher.start()
    try:
        names = doc.run(doc.SINUS, poppy=poppy)
    finally:
        watcher.stop()
    z, y = names["sinus_prim_z"], names["sinus_prim_y"]
    assert not z.is_alive() and not y.is_alive() and not z.running
    assert z.recent_update_frequencies
    swing_z = max(watcher.record_positions["head_z"]) - min(watcher.record_positions["head_z"])
    swing_y = max(watcher.record_positions["head_y"]) - min(watcher.record_positions["head_y"])
    assert swing_z > 30.0 and swing_y > 15.0  # amplitudes 30° and 20°


def _move_head_by_hand(robot: Robot, stop: threading.Event) -> None:
    """A hand turning the compliant head from 0° to 40° while the recording runs."""
    motor = robot.head_z
    step = 0
    while not stop.wait(0.02) and step <= 40:
        virtual(robot, "head_z").move_by_hand(motor.to_motor(float(step)))
        step += 1


def test_record_then_replay_from_the_saved_file(
    poppy: Robot, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    stop = threading.Event()
    hand = threading.Thread(target=_move_head_by_hand, args=(poppy, stop))
    hand.start()
    try:
        names = doc.run(doc.RECORD, poppy=poppy)
    finally:
        stop.set()
        hand.join()
    with open(tmp_path / "mymove.json") as f:
        saved = Move.load(f)
    assert set(saved.motors) == {m.name for m in poppy.motors}
    track = saved.trajectory("head_z")
    assert track.max() - track.min() > 20.0  # the hand's motion is in the file
    for motor in poppy.motors:
        motor.compliant = False
    poppy.goto_position(dict.fromkeys((m.name for m in poppy.motors), 0.0), 0.5, wait=True)
    names = doc.run(doc.REPLAY, Move=names["Move"], MovePlayer=names["MovePlayer"], poppy=poppy)
    last = saved.frame(-1)["head_z"]
    assert abs(poppy.head_z.goal_position - last) <= 2.0
    assert names["player"].duration() == pytest.approx(saved.duration_s)


def test_vrep_is_refused_naming_mujoco() -> None:
    with pytest.raises(ConfigError, match="simulator='mujoco'"):
        PoppyTorso(simulator="vrep")


# -- the other creatures ------------------------------------------------------------------------


@pytest.mark.parametrize("simulator", SIMULATORS)
def test_ergo_jr_constructor_and_behaviours(simulator: str) -> None:
    if simulator == "mujoco":
        pytest.importorskip("mujoco")
    names = doc.run(doc.CREATE_ERGO_JR, SIMULATOR=simulator)
    with names["poppy"] as poppy:
        assert [m.name for m in poppy.motors] == ["m1", "m2", "m3", "m4", "m5", "m6"]
        assert all(m.max_torque == pytest.approx(70.0) for m in poppy.motors)  # 70 % as documented
        assert all(m.goto_behavior == "dummy" for m in poppy.motors)  # pypot's Ergo Jr default
        for name in ("dance", "jump", "base_posture", "rest_posture", "safe_power_up"):
            assert name in poppy.primitive_names and getattr(poppy, name).name == name
        poppy.compliant = False
        poppy.dance.start()
        assert poppy.dance.running and poppy.dance in poppy.active_primitives
        assert wait_until(lambda: abs(poppy.m1.goal_position) > 5.0, 10.0)
        poppy.dance.stop()
        assert not poppy.dance.running
        poppy.rest_posture.start()
        poppy.rest_posture.wait_to_stop()
        doc.run(doc.BASE_POSTURE, poppy=poppy)
        assert poppy.base_posture.wait_to_stop(30.0) and poppy.base_posture.error is None
        zeros = {m.name: 0.0 for m in poppy.motors}
        assert wait_until(lambda: reached(poppy, zeros, TOLERANCE_DEG[simulator]), 5.0)


def test_ergo_jr_from_config_as_the_documentation(capsys: pytest.CaptureFixture[str]) -> None:
    from poppy_core.robot import load_profile

    my_config = load_profile("ergo-jr").to_pypot_dict()
    names = doc.run(doc.FROM_CONFIG, my_config=my_config)
    with names["ergo_robot"] as ergo:
        assert wait_until(lambda: abs(ergo.m6.present_position - 20.0) < 2.0, 10.0)
    assert capsys.readouterr().out.strip()


@pytest.mark.parametrize("simulator", SIMULATORS)
def test_humanoid_behaviours_and_setup(simulator: str, capsys: pytest.CaptureFixture[str]) -> None:
    if simulator == "mujoco":
        pytest.importorskip("mujoco")
    tolerance = TOLERANCE_DEG[simulator]
    with doc.run(doc.CREATE_HUMANOID, SIMULATOR=simulator)["poppy"] as robot:
        assert "l_hip_x" in capsys.readouterr().out
        for name in ("stand_position", "sit_position", "limit_torque", "temperature_monitoring"):
            assert name in robot.primitive_names
        assert robot.temperature_monitoring.running  # started by default, as documented
        assert all(m.compliant_behavior == "safe" for m in robot.torso)
        # pypot's simulated robots hold their start pose: the Humanoid stands, servos on
        assert not robot.compliant
        if simulator == "mujoco":
            assert robot.get_object_position("head")[2] > 0.6
        doc.run(doc.SIMULATED_HEAD, poppy=robot)  # the simulation quickstart turns the head
        assert float(capsys.readouterr().out.split()[-1]) == pytest.approx(-10.0, abs=tolerance)

        doc.run(doc.HUMANOID_SETUP, robot=robot)
        assert robot._primitive_manager._filter([1.0, 2.0]) == 3.0
        doc.run(doc.SIT_POSITION, poppy=robot)
        assert robot.sit_position.wait_to_stop(30.0) and robot.sit_position.error is None
        sit = clamp_to_limits(robot, humanoid_sit())
        assert wait_until(lambda: reached(robot, sit, tolerance), 5.0), positions(robot, sit)
        robot.stand_position.start()
        assert robot.stand_position.wait_to_stop(30.0) and robot.stand_position.error is None
        zeros = {m.name: 0.0 for m in robot.motors}
        assert wait_until(lambda: reached(robot, zeros, tolerance), 5.0), positions(robot)
        if simulator == "mujoco":
            # sitting, the free-standing robot (no chair in the scene) ends on the floor
            assert robot.get_object_position("pelvis")[2] < 0.3
            doc.run(doc.RESET_SIMULATION, poppy=robot)
            assert wait_until(lambda: robot.get_object_position("head")[2] > 0.6, 5.0)
            doc.run(doc.OBJECT_POSITION, poppy=robot)
            lines = capsys.readouterr().out.splitlines()
            # V-REP's name is the body's; the robot may still settle on its feet after the reset
            forearm = robot.simulation.get_object_position("l_forearm")
            assert ast.literal_eval(lines[0]) == pytest.approx(forearm, abs=0.005)
            forearm_from_head = ast.literal_eval(lines[1])
            assert 0.15 < sum(v * v for v in forearm_from_head) ** 0.5 < 0.6


def test_torso_behaviours(torso: Robot) -> None:
    # the documentation's list (line 1969), and init_position, which poppy_torso.py attaches too
    assert torso.primitive_names == TORSO_PRIMITIVES
    assert torso.temperature_monitoring.running
    stop_all(torso)
    torso.compliant = False  # "Remember to remove compliance before starting the primitives!"
    before = torso.head_z.torque_limit
    doc.run(doc.LIMIT_TORQUE, poppy=torso)
    try:
        assert wait_until(lambda: torso.head_z.torque_limit < 50.0, 5.0)  # at its goal
        torso.head_z.goto_position(30, 0.5, wait=True)
        assert wait_until(lambda: _near(torso, "head_z", 30.0), 5.0)  # still reaches goals
    finally:
        torso.limit_torque.stop()
    assert wait_until(lambda: torso.head_z.torque_limit == pytest.approx(before), 5.0)
    torso.head_idle_motion.start()
    try:
        start = torso.head_z.present_position
        assert wait_until(lambda: abs(torso.head_z.present_position - start) > 1.0, 10.0)
    finally:
        torso.head_idle_motion.stop()


def test_a_minimal_config_file(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    (tmp_path / "my_config.json").write_text(doc.MINIMAL_CONFIG_JSON)
    with doc.run(doc.FROM_JSON)["poppy"] as poppy:
        assert [(m.name, m.id, m.model.name) for m in poppy.motors] == [
            ("head_z", 36, "AX-12A"),
            ("head_y", 37, "AX-12A"),
        ]
        assert poppy.alias == ["head"] and poppy.head == [poppy.head_z, poppy.head_y]
        poppy.head.compliant = False
        poppy.head_z.goal_position = 30
        assert wait_until(lambda: _near_deg(poppy.head_z.present_position, 30.0), 10.0)


def _near_deg(value: float, target: float) -> bool:
    return abs(value - target) <= TOLERANCE_DEG["dummy"]


def test_servers_stop_with_the_robot() -> None:
    import urllib.request

    robot = PoppyErgoJr(simulator="dummy", use_http=True, http_port=0, use_ws=True, ws_port=0)
    try:
        with urllib.request.urlopen(f"{robot.http.url}/motors/list.json", timeout=10) as answer:
            assert b"m1" in answer.read()
        assert robot.ws.running
    finally:
        robot.close()
    assert not robot.http.running and not robot.ws.running


def test_unknown_arguments_are_refused_in_one_line() -> None:
    with pytest.raises(ValueError, match="unexpected argument colour='red'"):
        PoppyErgoJr(simulator="dummy", colour="red")
    with pytest.raises(ConfigError, match="use_zmq"):
        PoppyErgoJr(simulator="dummy", use_remote=True)


def test_robot_overview(poppy: Robot, capsys: pytest.CaptureFixture[str]) -> None:
    doc.run(doc.ROBOT_OVERVIEW, robot=poppy)
    lines = capsys.readouterr().out.splitlines()
    names = [m.name for m in poppy.motors]
    assert lines[: len(names)] == names
    assert float(lines[len(names)]) == pytest.approx(poppy.head_z.present_position, abs=2.0)
    assert lines[len(names) + 1 :] == ["head_z", "head_y"]
    assert poppy.compliant


def test_saving_and_loading_the_config(
    poppy: Robot, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    doc.run(doc.SAVE_CONFIG, my_robot=poppy)
    with doc.run(doc.LOAD_CONFIG)["ergo"] as ergo:
        assert [m.name for m in ergo.motors] == [m.name for m in poppy.motors]
        assert ergo.alias == poppy.alias
    my_robot = doc.run(doc.CLOSING)["my_robot"]
    assert my_robot.closed and len(my_robot.motors) == len(poppy.motors)


@pytest.mark.parametrize(
    "simulator", ["dummy", pytest.param("mujoco", marks=pytest.mark.gl)]
)  # reading the MuJoCo camera renders the scene with OpenGL
def test_sensors_of_the_ergo_jr(simulator: str, capsys: pytest.CaptureFixture[str]) -> None:
    if simulator == "mujoco":
        pytest.importorskip("mujoco")
    with doc.run(doc.CREATE_ERGO_JR, SIMULATOR=simulator)["poppy"] as poppy:
        doc.run(doc.SENSORS, poppy=poppy)
    lines = capsys.readouterr().out.splitlines()
    assert "['camera', 'marker_detector']" in lines
    assert "'frame'" in lines[3] and "'resolution'" in lines[3]
    assert lines[4] == "[640, 480]"


# -- writing your own primitive (the old Poppy Ergo's motors named as the Ergo Jr's) ------------

SIM_MODES: dict[str, bool | str] = {"dummy": True, "mujoco": "mujoco"}


@pytest.fixture(scope="module", params=SIMULATORS)
def ergo_robot(request: pytest.FixtureRequest) -> Iterator[Robot]:
    """The examples' ``ergo_robot = pypot.robot.from_config(...)``: the Ergo Jr's pypot config,
    on virtual servos, stiff ("Remember to remove compliance before starting the primitives")."""
    if request.param == "mujoco":
        pytest.importorskip("mujoco")
    my_config = load_profile("ergo-jr").to_pypot_dict()
    with from_config(my_config, sim=SIM_MODES[request.param]) as robot:
        robot.compliant = False
        yield robot


def _swings_opposite(robot: Robot, amplitude: float) -> None:
    """m1 swings both ways by ``amplitude`` and m4 the other way (base_pan x, head_pan -x):
    watched until both swings are seen (a loaded machine runs the physics slower than the
    clock: the wait is polled, the swing is the check)."""
    watcher = PositionWatcher(robot, 25, ["m1", "m4"])
    watcher.start()

    def swung() -> bool:
        base = list(watcher.record_positions.get("m1", []))
        return len(base) > 2 and max(base) > amplitude and min(base) < -amplitude

    wait_until(swung)
    watcher.stop()
    base, head = watcher.record_positions["m1"], watcher.record_positions["m4"]
    assert max(base) > amplitude and min(base) < -amplitude, base
    assert float(np.corrcoef(base, head)[0, 1]) < -0.8  # head_pan = -base_pan


def _custom(*parts: str) -> str:
    return doc.ergo_motor_names("".join(parts))


# What the documentation's primitive examples use without defining it: numpy, LoopPrimitive
# (written unqualified) and the selector's song.
MISSING_NAMES = {"numpy": np, "LoopPrimitive": LoopPrimitive, "song": "my_favorite_song_to_dance"}


def test_own_primitive_runs_its_30_seconds(ergo_robot: Robot) -> None:
    names = doc.run(
        _custom(doc.DANCE_PRIMITIVE, doc.DANCE_START), ergo_robot=ergo_robot, **MISSING_NAMES
    )
    dance = names["dance"]
    assert dance.running
    _swings_opposite(ergo_robot, 15.0)  # amp 60
    assert dance.wait_to_stop(30.0)  # ends by itself (30 documentation seconds)
    assert dance.error is None and not dance.running


def test_loop_primitive_dances_until_stopped(ergo_robot: Robot) -> None:
    names = doc.run(
        _custom(doc.DANCE_PRIMITIVE, doc.LOOP_DANCE_PRIMITIVE, doc.LOOP_DANCE_START),
        ergo_robot=ergo_robot,
        **MISSING_NAMES,
    )
    dance = names["dance"]
    try:
        _swings_opposite(ergo_robot, 15.0)  # amp 40
        assert dance.recent_update_frequencies
    finally:
        dance.stop()
    assert not dance.is_alive() and dance.error is None


def test_attached_primitive_started_by_another(ergo_robot: Robot) -> None:
    names = doc.run(
        _custom(doc.DANCE_PRIMITIVE, doc.ATTACH_DANCE, doc.SELECTOR_PRIMITIVE),
        ergo_robot=ergo_robot,
        **MISSING_NAMES,
    )
    dance = ergo_robot.dance
    assert isinstance(dance, names["DancePrimitive"]) and dance.name == "dance"
    assert dance in ergo_robot.primitives and dance.running
    _swings_opposite(ergo_robot, 10.0)  # amp 30
    assert dance.wait_to_stop(30.0)
    selector = names["SelectorPrimitive"](ergo_robot)
    selector.start()  # the dance has ended: the selector starts it again
    assert selector.wait_to_stop(10.0) and selector.error is None
    assert dance.running
    assert dance.wait_to_stop(30.0) and dance.error is None
