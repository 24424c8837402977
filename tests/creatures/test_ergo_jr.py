"""Poppy Ergo Jr on the emulator: its setup, postures, dance, jump and safe power-up."""

from __future__ import annotations

import math
import time

import pytest

from poppy_core.creatures import Dance, attach_creature
from poppy_core.creatures.ergo_jr import DANCE_WAVES, ERGO_JR_PID
from poppy_core.creatures.postures import ERGO_JR_CURIOUS, ERGO_JR_IDLE, ERGO_JR_REST
from poppy_core.errors import ArgumentError
from poppy_core.motion import primitive_manager
from poppy_core.robot import Robot
from poppy_core.schedule import Gate
from tests.creatures.helpers import positions, reached, virtual, wait_until
from tests.helpers import eventually

ERGO_JR_PRIMITIVES = [
    "safe_power_up",
    "dance",
    "base_posture",
    "rest_posture",
    "curious_posture",
    "tetris_posture",
    "jump",
    "tinsel_demo",
    "stubborn_demo",
    "chicken_demo",
    "puzzel_demo",
    "tracking_feedback",
    "marker_follow",
]


@pytest.fixture(autouse=True)
def _stiff(ergo: Robot) -> None:
    ergo.compliant = False


def test_behaviours_are_attached(ergo: Robot) -> None:
    assert ergo.primitive_names == ERGO_JR_PRIMITIVES
    assert ergo.creature.kind == "ergo-jr"
    assert ergo.creature.goto_control == "dummy"  # pypot's default, kept by poppy_ergo_jr
    assert primitive_manager(ergo).filter([1.0, 2.0]) == 3.0  # requests are summed
    assert ergo.active_primitives == []  # Ergo Jr starts none by default


def test_attaching_again_keeps_the_same_primitives(ergo: Robot) -> None:
    dance = ergo.dance
    assert attach_creature(ergo, "PoppyErgoJr").primitives["dance"] is dance
    assert ergo.dance is dance


def test_setup_limits_torque_and_sets_the_gains(ergo: Robot) -> None:
    for motor in ergo.motors:
        assert motor.torque_limit == pytest.approx(70.0)
        assert motor.pid == pytest.approx(ERGO_JR_PID, abs=0.02)
    assert wait_until(
        lambda: all(
            virtual(ergo, m.name).table.get_si("torque_limit") == pytest.approx(70.0, abs=0.2)
            for m in ergo.motors
        )
    )


@pytest.mark.parametrize(
    ("name", "targets"),
    [
        ("curious_posture", ERGO_JR_CURIOUS),
        ("rest_posture", ERGO_JR_REST),
        ("base_posture", {f"m{i}": 0.0 for i in range(1, 7)}),
    ],
)
def test_postures_reach_their_targets(ergo: Robot, name: str, targets: dict[str, float]) -> None:
    posture = getattr(ergo, name)
    posture.duration = 0.5
    posture.start()
    assert posture.wait_to_stop(5.0)
    assert posture.state == "stopped" and posture.error is None
    assert wait_until(lambda: reached(ergo, targets), 2.0), positions(ergo)


def test_rest_posture_lights_blue_while_moving_and_off_after(ergo: Robot) -> None:
    ergo.rest_posture.duration = 0.6
    ergo.rest_posture.start()
    assert wait_until(lambda: ergo.m1.led == "blue", 1.0)
    assert ergo.rest_posture.wait_to_stop(5.0)
    assert wait_until(lambda: ergo.m1.led == "off", 1.0)


def test_dance_moves_the_motors_and_stops_cleanly(ergo: Robot) -> None:
    dance: Dance = ergo.dance
    dance.set_property("intro_s", "0.3")
    dance.start()
    try:
        time.sleep(0.4)  # the intro
        before = positions(ergo)
        time.sleep(0.8)
        after = positions(ergo)
        assert abs(after["m1"] - before["m1"]) > 20  # 90° at 0.25 Hz
        assert abs(after["m4"] - before["m4"]) > 20
        assert dance.state == "running" and dance.is_alive()
    finally:
        dance.stop()
    final: str = dance.state
    assert final == "stopped" and not dance.is_alive() and dance.error is None
    assert dance not in primitive_manager(ergo).primitives
    goals = {m.name: m.goal_position for m in ergo.motors}
    time.sleep(0.3)
    assert {m.name: m.goal_position for m in ergo.motors} == goals  # nothing moves them any more
    assert all(m.moving_speed == pytest.approx(0.0, abs=1.0) for m in ergo.motors)


def test_dance_positions_are_the_sum_of_its_sinusoids(ergo: Robot) -> None:
    dance = Dance(ergo, amplitude_scale=0.5)
    assert dance.positions(0.0) == pytest.approx(dict.fromkeys(dance.positions(0.0), 0.0))
    quarter = dance.positions(1.0)  # m1: 0.25 Hz -> a quarter period: +amp; m4 in opposition
    slow = 0.5 * 10.0 * math.sin(2 * math.pi * 0.1)
    assert quarter["m1"] == pytest.approx(0.5 * 90.0 + slow)
    assert quarter["m4"] == pytest.approx(-0.5 * 90.0 + slow)
    assert len(DANCE_WAVES) == 5
    with pytest.raises(ArgumentError):
        dance.set_property("tempo_scale", "-1")


def test_safe_power_up_limits_torque_and_reaches_the_idle_posture(ergo: Robot) -> None:
    for motor in ergo.motors:
        motor.torque_limit = 100.0
    ergo.safe_power_up.duration = 0.5
    ergo.safe_power_up.start()
    assert ergo.safe_power_up.wait_to_stop(5.0)
    assert ergo.safe_power_up.error is None
    assert all(m.torque_limit == pytest.approx(70.0) for m in ergo.motors)
    assert all(not m.compliant for m in ergo.motors)
    # IdlePosture's m2 -110° is inside m2's user range [-125, 90] (the profile's [-90, 125] is
    # in the motor frame, m2 is indirect): pypot's idle posture is reached as it is.
    assert ergo.m2.angle_limit == (-125.0, 90.0)
    assert wait_until(lambda: reached(ergo, ERGO_JR_IDLE), 2.0), positions(ergo)
    assert wait_until(
        lambda: virtual(ergo, "m3").table.get_si("torque_limit") == pytest.approx(70.0, abs=0.2)
    )
    assert all(m.moving_speed == pytest.approx(0.0, abs=1.0) for m in ergo.motors)


def test_jump_folds_unfolds_and_gives_the_gains_back(ergo: Robot) -> None:
    jump = ergo.jump
    jump.jumps = 1
    seen_m2: list[float] = []
    jump.start()
    while jump.is_alive():
        seen_m2.append(ergo.m2.present_position)
        time.sleep(0.02)
    assert jump.state == "stopped" and jump.error is None
    assert min(seen_m2) < -60 and max(seen_m2) > -40  # folded (-75°), then up (-10°)
    assert all(m.pid == pytest.approx(ERGO_JR_PID, abs=0.02) for m in ergo.motors)
    with pytest.raises(ArgumentError):
        jump.set_property("jumps", "-2")


class TracedDance(Dance):
    """A dance noting the dance time of each update."""

    def __init__(self, robot: Robot, intro_s: float) -> None:
        super().__init__(robot, intro_s=intro_s)
        self.dance_times: list[float] = []

    def positions(self, t_s: float) -> dict[str, float]:
        self.dance_times.append(t_s)
        return super().positions(t_s)


def test_a_late_gated_dance_dances_in_phase_with_the_shared_start(ergo: Robot) -> None:
    intro_s, late_s = 0.2, 0.5
    dance = TracedDance(ergo, intro_s)
    at = time.monotonic()
    gate = Gate(at=at)
    dance.start(gate=gate)
    while time.monotonic() < at + late_s:
        time.sleep(0.05)
    gate.open()  # its thread wakes later than the shared start plus the intro
    try:
        assert eventually(lambda: len(dance.dance_times) >= 2)
    finally:
        dance.stop()
    # the dance counts from shared start + intro, not from when this robot's intro ended
    assert dance.dance_times[0] >= late_s - intro_s
