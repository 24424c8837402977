"""The plugin follows LeRobot 0.4.4's Robot and Teleoperator contracts (on emulated Ergo Jrs).

LeRobot's own registries and factories build the devices (``register_third_party_plugins``,
``make_robot_from_config``), in LeRobot's venv (one process for all: ``probe``); the motors
are the test's emulators on ptys.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from tests.helpers.bus import emulate_bus
from tests.helpers.json_lines import JsonChild
from tests.helpers.server import serve
from tests.lerobot_plugin.conftest import LeRobot

pytestmark = [pytest.mark.slow, pytest.mark.timeout(600)]

ERGO_JR = "XL-320:1-6"
XL320_STEP = 300 / 1024  # degrees a position tick (poppy's register table)


def test_types_features_torque_limits_and_calibration(lerobot: LeRobot, probe: JsonChild) -> None:
    # the leader's calibration, as LeRobot keeps it: m1 10 ticks off (on the host: no register)
    calibration = lerobot.home / "calibration" / "teleoperators" / "poppy_ergo_jr_leader"
    calibration.mkdir(parents=True, exist_ok=True)  # another test may have made it
    ticks = {
        f"m{i}": {"id": i, "drive_mode": 0, "homing_offset": 0, "range_min": 0, "range_max": 1024}
        for i in range(1, 7)
    }
    ticks["m1"]["homing_offset"] = 10
    (calibration / "leader.json").write_text(json.dumps(ticks))
    with (
        emulate_bus(ERGO_JR, protocol=2, via="pty") as (follower_bus, follower_port),
        emulate_bus(ERGO_JR, protocol=2, via="pty") as (leader_bus, leader_port),
    ):
        leader_bus.motor(1).move_by_hand(30.0)
        seen = probe.ask("contract", follower_port, leader_port)
        follower_torque = [m.torque_enabled for m in follower_bus.motors]
        leader_torque = [m.torque_enabled for m in leader_bus.motors]
        follower_goals = {m.id: m.goal_position_deg for m in follower_bus.motors}

    assert seen["robots"] == ["poppy_ergo_jr", "poppy_humanoid", "poppy_torso"]
    assert seen["teleops"] == [
        "poppy_ergo_jr_leader",
        "poppy_humanoid_leader",
        "poppy_torso_leader",
    ]
    joints = [f"m{i}.pos" for i in range(1, 7)]
    features = seen["features"]
    # usable while disconnected; the device class found from the config class's name
    assert features["poppy_ergo_jr"] == {
        "class": "PoppyErgoJr",
        "observation": joints,
        "action": joints,
        "connected": False,
    }
    assert features["poppy_ergo_jr_leader"] == {"class": "PoppyErgoJrLeader", "action": joints}
    assert features["poppy_torso"]["class"] == "PoppyTorso"
    assert "l_shoulder_y.pos" in features["poppy_torso"]["action"]
    # the Torso's leader is its arms
    assert features["poppy_torso_leader"]["action"][:4] == [
        "l_shoulder_y.pos",
        "l_shoulder_x.pos",
        "l_arm_z.pos",
        "l_elbow_y.pos",
    ]
    assert len(features["poppy_torso_leader"]["action"]) == 8
    assert features["with_camera"] == [48, 64, 3]
    # `--help` describes the plugin's fields (LeRobot's parser reads them from the config
    # classes' comments, following each class's first base: the Poppy fields come first)
    follower_help, leader_help = (
        seen["help"]["PoppyErgoJrConfig"],
        seen["help"]["PoppyErgoJrLeaderConfig"],
    )
    assert "serial port" in follower_help["port"] and "serial port" in leader_help["port"]
    assert "cameras" in follower_help["robot_cameras"]
    assert "Torque off" in follower_help["disable_torque_on_disconnect"]
    assert "primitive of the leader" in leader_help["primitive"]

    # calibration: written where LeRobot keeps it on the first connect, from poppy's profile
    assert (seen["calibrated_before"], seen["calibrated_after"]) == (False, True)
    written = Path(seen["calibration_file"])
    robots = Path(seen["calibration_root"]) / "robots"
    assert written == robots / "poppy_ergo_jr" / "contract-follower.json"
    stored = json.loads(written.read_text())
    assert stored["m1"] == {
        "id": 1,
        "drive_mode": 0,
        "homing_offset": 0,
        "range_min": 0,
        "range_max": 1024,
    }
    assert stored["m2"]["drive_mode"] == 1  # the Ergo Jr's m2 is mounted indirect
    # goals: clamped to the angle limits (poppy's rule), then capped near the present position
    assert seen["sent_beyond_limits"] == {"m1.pos": 150.0, "m3.pos": -90.0}
    assert seen["sent_capped"]["m4.pos"] == pytest.approx(seen["present_m4"] + 5.0)
    assert "m9.pos" in seen["unknown_key"]
    assert seen["connected_after_disconnect"] is False
    assert follower_goals[1] == pytest.approx(150 - XL320_STEP)  # the register's top
    assert follower_goals[3] == pytest.approx(90.0, abs=XL320_STEP)  # m3 indirect: motor frame
    # torque: stiff on connect, left stiff (disable_torque_on_disconnect=False); the leader
    # compliant, to be moved by hand, and left so
    assert follower_torque == [True] * 6
    assert leader_torque == [False] * 6
    # the leader's m1, put at 30° by hand, read through its LeRobot calibration's offset
    assert seen["leader_calibrated"] is True
    assert seen["leader_action"]["m1.pos"] == pytest.approx(30.0 - 10 * XL320_STEP, abs=0.3)


def test_a_served_robot_is_driven_over_http(probe: JsonChild, tmp_path: Path) -> None:
    served = serve(str(tmp_path))
    robot = next(served)
    try:
        seen = probe.ask("served", robot.url)
        m1, m2 = robot.robot.motor("m1"), robot.robot.motor("m2")
        goals = (m1.goal_position, m2.goal_position)
        compliant = [m.compliant for m in robot.robot.motors]
    finally:
        served.close()
    assert seen["calibrated"] is True  # the server's config is its calibration
    assert set(seen["observation"]) == {f"m{i}.pos" for i in range(1, 7)}
    # clamped by the plugin (and by the server: poppy's one rule)
    assert seen["sent"] == {"m1.pos": 150.0, "m2.pos": 20.0}
    assert goals[1] == pytest.approx(20.0, abs=XL320_STEP)
    assert goals[0] == pytest.approx(150.0, abs=XL320_STEP)
    assert compliant == [True] * 6  # disconnected: torque off


def test_a_served_robots_own_camera_is_observed_through_lerobot(
    probe: JsonChild, tmp_path: Path
) -> None:
    """``robot_cameras`` on a served robot: the frames of its camera (its ``frame.png``
    route), RGB, as LeRobot's observation; the served camera here draws a known pattern."""
    served = serve(str(tmp_path))
    robot = next(served)
    try:
        camera = next(s for s in robot.robot.sensors if s.name == "camera")
        pattern = camera._black  # the simulated camera's frame (BGR), drawn on
        height, width = pattern.shape[:2]
        ys, xs = np.mgrid[0:height, 0:width]
        pattern[..., 0] = xs % 256  # blue
        pattern[..., 1] = ys % 256  # green
        pattern[..., 2] = 77  # red
        seen = probe.ask("served_camera", robot.url)
    finally:
        served.close()
    assert seen["features"]["camera"] == [height, width, 3]
    assert seen["shape"] == [height, width, 3] and seen["dtype"] == "uint8"
    for where, rgb in seen["pixels"].items():
        y, x = map(int, where.split(","))
        assert rgb == [77, y % 256, x % 256], where  # RGB, as LeRobot's cameras give
