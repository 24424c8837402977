"""IdealPlant motion, hand moves, and the plant interface."""

from __future__ import annotations

import time
from collections.abc import Sequence

import pytest

from poppy_core.emulator import IdealPlant, Plant, VirtualBus, VirtualMotor, build_bus_from_spec
from poppy_core.emulator.plant import SPEED_WINDOW_S
from poppy_core.protocol import encode_instruction, read, write


def set_si(bus: VirtualBus, motor_id: int, name: str, value: float) -> None:
    register = bus.motor(motor_id).model.register(name)
    data = register.encode(register.from_si(value))
    packet = write(bus.protocol, motor_id, register.address, data)
    bus.process(encode_instruction(bus.protocol, packet))


def get_si(bus: VirtualBus, motor_id: int, name: str) -> float:
    register = bus.motor(motor_id).model.register(name)
    value = register.to_si(bus.motor(motor_id).table.raw(register))
    assert isinstance(value, int | float)
    return float(value)


@pytest.fixture
def bus() -> VirtualBus:
    return build_bus_from_spec("XL-320:1", auto_step=False)


def test_default_plant_is_ideal(bus: VirtualBus) -> None:
    assert isinstance(bus.plant, IdealPlant)
    assert isinstance(bus.plant, Plant)


def test_reaches_goal_at_moving_speed(bus: VirtualBus) -> None:
    set_si(bus, 1, "moving_speed", 60.0)  # deg/s
    set_si(bus, 1, "torque_enable", True)
    set_si(bus, 1, "goal_position", 30.0)
    bus.advance(0.25)
    assert get_si(bus, 1, "present_position") == pytest.approx(15.0, abs=0.5)
    assert get_si(bus, 1, "present_speed") == pytest.approx(60.0, rel=0.05)
    assert get_si(bus, 1, "moving") == 1
    bus.advance(0.3)
    assert get_si(bus, 1, "present_position") == pytest.approx(30.0, abs=0.3)
    assert get_si(bus, 1, "moving") == 0
    bus.advance(SPEED_WINDOW_S)  # the speed is the mean over its window: still through it
    assert get_si(bus, 1, "present_speed") == 0.0
    assert get_si(bus, 1, "present_load") == 0.0


def test_a_goto_in_small_goal_steps_reads_its_speed(bus: VirtualBus) -> None:
    # A goto moves the goal a little at each step of the sync loop (50 Hz): the horn reaches
    # each of those goals within the step. Its present speed read 0 all along (the page's speed
    # column said 0.0 while the arm danced); it is the goto's speed.
    set_si(bus, 1, "torque_enable", True)
    for step in range(1, 26):  # 0 -> 50 degrees in 0.5 s: 100 deg/s
        set_si(bus, 1, "goal_position", 2.0 * step)
        bus.advance(0.02)
        if step >= 5:
            assert get_si(bus, 1, "present_speed") == pytest.approx(100.0, rel=0.1), step
    for _ in range(5):
        bus.advance(0.02)
    assert get_si(bus, 1, "present_speed") == 0.0


def test_zero_moving_speed_means_no_load_speed(bus: VirtualBus) -> None:
    no_load = bus.motor(1).model.no_load_speed_dps
    set_si(bus, 1, "torque_enable", True)
    set_si(bus, 1, "goal_position", -100.0)
    bus.advance(0.05)
    assert get_si(bus, 1, "present_position") == pytest.approx(-no_load * 0.05, abs=0.5)


def test_speed_is_capped_at_no_load_speed() -> None:
    bus = build_bus_from_spec("MX-28:1", auto_step=False)
    motor = bus.motor(1)
    set_si(bus, 1, "moving_speed", 600.0)  # MX-28 register allows ~700 deg/s, the motor can't
    assert motor.speed_limit_dps == pytest.approx(motor.model.no_load_speed_dps)


def test_small_steps_accumulate(bus: VirtualBus) -> None:
    set_si(bus, 1, "moving_speed", 6.0)
    set_si(bus, 1, "torque_enable", True)
    set_si(bus, 1, "goal_position", 10.0)
    for _ in range(200):
        bus.advance(0.005)  # 0.03° per step, well below one tick (0.29°)
    assert get_si(bus, 1, "present_position") == pytest.approx(6.0, abs=0.3)


def test_compliant_motor_holds_a_hand_move(bus: VirtualBus) -> None:
    set_si(bus, 1, "goal_position", 40.0)
    bus.motor(1).move_by_hand(-20.0)
    bus.advance(1.0)
    assert get_si(bus, 1, "present_position") == pytest.approx(-20.0, abs=0.3)
    assert get_si(bus, 1, "moving") == 0


def test_stiff_motor_returns_to_goal_after_hand_move(bus: VirtualBus) -> None:
    set_si(bus, 1, "torque_enable", True)
    bus.advance(0.01)
    bus.motor(1).move_by_hand(50.0)
    assert get_si(bus, 1, "present_position") == pytest.approx(50.0, abs=0.3)
    bus.advance(1.0)
    assert get_si(bus, 1, "present_position") == pytest.approx(0.0, abs=0.3)


def test_goal_is_kept_within_angle_limits(bus: VirtualBus) -> None:
    set_si(bus, 1, "torque_enable", True)
    motor = bus.motor(1)
    motor.table.set_si("goal_position", 100.0)
    motor.table.set_si("max_position_limit", 20.0)
    bus.advance(2.0)
    assert get_si(bus, 1, "present_position") == pytest.approx(20.0, abs=0.3)


def test_lazy_stepping_by_elapsed_time() -> None:
    bus = build_bus_from_spec("XL-320:1")
    set_si(bus, 1, "moving_speed", 100.0)
    set_si(bus, 1, "torque_enable", True)
    set_si(bus, 1, "goal_position", 90.0)
    time.sleep(0.3)
    register = bus.motor(1).model.register("present_position")
    out = bus.process(encode_instruction(2, read(2, 1, register.address, register.size)))
    assert out
    position = get_si(bus, 1, "present_position")
    assert 20.0 < position <= 90.0  # ~30° expected; generous for a loaded machine


class RecordingPlant:
    """A custom plant: proves the bus drives any Plant implementation."""

    def __init__(self) -> None:
        self.steps: list[float] = []
        self.motors: list[VirtualMotor] = []

    def attach(self, motors: Sequence[VirtualMotor]) -> None:
        self.motors = list(motors)
        for motor in motors:
            motor.hand_mover = self.hand

    def step(self, dt_s: float) -> None:
        self.steps.append(dt_s)

    def hand(self, motor: VirtualMotor, position_deg: float) -> None:
        motor.set_state(position_deg / 2, 0.0, 0.0, False)


def test_custom_plant() -> None:
    plant = RecordingPlant()
    bus = build_bus_from_spec("XL-320:1-2", plant=plant, auto_step=False)
    assert isinstance(plant, Plant)
    assert [m.id for m in plant.motors] == [1, 2]
    bus.advance(0.02)
    assert plant.steps == [0.02]
    bus.motor(2).move_by_hand(40.0)
    assert get_si(bus, 2, "present_position") == pytest.approx(20.0, abs=0.3)
