"""The plugin on a robot served over Zenoh (``zenoh:NAME``), and on a Torso and a Humanoid.

In LeRobot 0.4.4's venv (``plugin_probe.py``): a simulated Ergo Jr served on Zenoh on loopback
(an explicit endpoint, scouting off) driven by a follower and read by a leader; a Torso on an
emulated protocol-1 bus on a pty and a Humanoid on ``sim:ideal`` connected and driven.
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Iterator
from pathlib import Path

import pytest

from poppy_core.robot import load_profile
from tests.helpers.bus import emulate_bus
from tests.helpers.json_lines import JsonChild
from tests.helpers.zenoh_served import TOKEN, Served

pytestmark = [pytest.mark.slow, pytest.mark.timeout(600)]

XL320_STEP = 300 / 1024  # degrees a position tick (poppy's register table)
MX_STEP = 360 / 4096


@pytest.fixture
def on_zenoh(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Served]:
    pytest.importorskip("zenoh")
    monkeypatch.setenv("POPPY_MOVES_DIR", str(tmp_path))
    served = Served("jr-lerobot")
    try:
        yield served
    finally:
        served.close()


def test_a_robot_served_on_zenoh_is_followed_and_leads(probe: JsonChild, on_zenoh: Served) -> None:
    robot = on_zenoh.robot
    seen = probe.ask("zenoh", on_zenoh.name, on_zenoh.endpoint, env={"POPPY_TOKEN": TOKEN})
    goals = (robot.motor("m1").goal_position, robot.motor("m2").goal_position)
    present = {m.name: m.present_position for m in robot.motors}
    compliant = [m.compliant for m in robot.motors]

    assert seen["calibrated"] is True  # the server's config is its calibration
    assert list(seen["observation"]) == [f"m{i}.pos" for i in range(1, 7)]
    # reached at the endpoint given (zenoh_connect), signed with POPPY_TOKEN;
    # clamped by the plugin (m1's top is 150°), received by the served robot, which moved there
    assert seen["sent"] == {"m1.pos": 150.0, "m2.pos": 20.0}
    assert goals == pytest.approx((150.0, 20.0), abs=XL320_STEP)
    assert seen["reached"]["m1.pos"] == pytest.approx(150.0, abs=2.0)
    assert seen["reached"]["m2.pos"] == pytest.approx(20.0, abs=2.0)
    # disconnected: torque off; then the leader read the served robot where it stays
    assert compliant == [True] * 6
    assert set(seen["leader_action"]) == {f"m{i}.pos" for i in range(1, 7)}
    assert seen["leader_action"]["m1.pos"] == pytest.approx(150.0, abs=2.0)
    for name, value in present.items():
        assert seen["leader_action"][f"{name}.pos"] == pytest.approx(value, abs=1.0), name


def test_the_plugin_through_a_router_with_a_stranger_answering_for_the_robot(
    probe: JsonChild, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The topology users deploy: the robot and LeRobot connected only to a router process
    (``zenoh_connect`` is the router), and a stranger's session on it that answers every
    robot's ``api`` (``tests/fleet/test_router_stranger.py``'s ``Stranger``): the plugin takes
    only the robot's signed answers, so it observes and drives the real robot."""
    pytest.importorskip("zenoh")
    from tests.fleet.test_router_stranger import Stranger
    from tests.helpers.zenoh_router import Router

    monkeypatch.setenv("POPPY_MOVES_DIR", str(tmp_path))
    router = Router()
    served = stranger = None
    try:
        served = Served("jr-lerobot", router=router.endpoint)
        stranger = Stranger(router.endpoint)
        robot = served.robot
        seen = probe.ask("zenoh", served.name, router.endpoint, env={"POPPY_TOKEN": TOKEN})
        goals = (robot.motor("m1").goal_position, robot.motor("m2").goal_position)
        assert stranger.asked("poppy/jr-lerobot/api")  # the stranger answered the plugin too
    finally:
        for opened in (stranger, served):
            if opened is not None:
                opened.close()
        router.kill()
    assert list(seen["observation"]) == [f"m{i}.pos" for i in range(1, 7)]
    assert seen["sent"] == {"m1.pos": 150.0, "m2.pos": 20.0}
    assert goals == pytest.approx((150.0, 20.0), abs=XL320_STEP)
    assert seen["reached"]["m1.pos"] == pytest.approx(150.0, abs=2.0)
    assert seen["leader_action"]["m1.pos"] == pytest.approx(150.0, abs=2.0)


def spec_of(profile: str, controller: str) -> str:
    """The motors of ``profile``'s ``controller`` as an emulator spec: ``MX-28:ID/ID,...``."""
    config = load_profile(profile)
    by_type: dict[str, list[int]] = defaultdict(list)
    for group in config.controllers[controller].attached_motors:
        for name in config.resolve_group(group):
            by_type[config.motors[name].type].append(config.motors[name].id)
    return ",".join(f"{kind}:{'/'.join(map(str, ids))}" for kind, ids in by_type.items())


def test_torso_and_humanoid_connect_observe_and_act(probe: JsonChild) -> None:
    upper, lower = "upper_body_controller", "lower_body_controller"
    with (
        emulate_bus(spec_of("torso", upper), protocol=1, via="pty") as (bus, port),
        emulate_bus(spec_of("humanoid", upper), protocol=1, via="pty") as (_, upper_port),
        emulate_bus(spec_of("humanoid", lower), protocol=1, via="pty") as (legs, lower_port),
    ):
        humanoid_ports = f"{upper}={upper_port},{lower}={lower_port}"
        seen = probe.ask("bodies", port, humanoid_ports)
        goal_elbow = bus.motor(44).goal_position_deg
        torque = {m.id: m.torque_enabled for m in bus.motors}
        goal_knee = legs.motor(14).goal_position_deg

    torso, humanoid = seen["poppy_torso"], seen["poppy_humanoid"]
    torso_joints = [f"{name}.pos" for name in load_profile("torso").motors]
    assert torso["features"] == torso["observation"] == torso_joints
    humanoid_joints = [f"{name}.pos" for name in load_profile("humanoid").motors]
    assert humanoid["features"] == humanoid["observation"] == humanoid_joints
    for body in (torso, humanoid):
        for key, value in body["sent"].items():
            assert body["reached"][key] == pytest.approx(value, abs=2.0), key
    assert torso["sent"] == {"l_elbow_y.pos": -40.0, "head_z.pos": 20.0}
    # l_elbow_y: direct, offset -90 (user = motor + 90): the emulated motor's goal is -130°
    assert goal_elbow == pytest.approx(-130.0, abs=MX_STEP)
    assert set(torque.values()) == {False}  # compliant once disconnected
    assert goal_knee == pytest.approx(30.0, abs=MX_STEP)  # l_knee_y: on the second bus
    # the MX's calibration in its 4096 ticks over 360°, the AX-12's in 1024 over 300°
    assert torso["calibration"]["l_elbow_y"]["homing_offset"] == round(-90 / MX_STEP)
    head_z = torso["calibration"]["head_z"]  # limits -100..100: 50° and 250° from the bottom
    assert (head_z["range_min"], head_z["range_max"]) == (171, 853)
    # one port for the Humanoid's two buses, or a controller it lacks: a one-line reason
    refused = seen["refused"]
    assert len(refused) == 2
    for reason in refused.values():
        assert "upper_body_controller, lower_body_controller" in reason
        assert "CONTROLLER=PORT" in reason
