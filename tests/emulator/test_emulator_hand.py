"""The emulator's hand: compliant horns follow it, stiff ones resist it, gestures over time."""

from __future__ import annotations

import re
from collections.abc import Iterator

import pytest

from poppy_core.bus import DxlBus
from poppy_core.emulator import VirtualBus, build_bus_from_spec, serve_link
from poppy_core.emulator.plant import HAND_FRICTION_PCT
from poppy_core.errors import ArgumentError
from tests.helpers.waiting import eventually


@pytest.fixture
def bus() -> Iterator[VirtualBus]:
    virtual = build_bus_from_spec("XL-320:1-3", protocol=2)
    yield virtual
    virtual.hand.close()


def load(bus: VirtualBus, motor_id: int) -> float:
    bus.advance()
    return float(bus.motor(motor_id).table.get_si("present_load") or 0.0)


def test_a_compliant_horn_follows_the_hand_and_stays_where_it_is_left(bus: VirtualBus) -> None:
    hand = bus.hand
    hand.move(1, 40.0, over_s=2.0)
    # under way: between both ends, moving with a small effort against the hand

    def under_way() -> bool:
        effort = load(bus, 1)  # read first: the gesture may end between the reads
        return 5.0 < hand.where()[1] < 35.0 and abs(effort + HAND_FRICTION_PCT) < 0.2

    assert eventually(under_way)
    assert hand.wait(10.0)
    assert hand.where()[1] == pytest.approx(40.0, abs=0.3)
    assert bus.motor(1).goal_position_deg == 0.0  # the goal is untouched
    assert load(bus, 1) == 0.0  # held still: no effort
    assert hand.release() == [1]
    assert hand.where()[1] == pytest.approx(40.0, abs=0.3)  # friction keeps it there
    assert hand.holding() == {}


def test_a_stiff_horn_resists_and_its_load_rises_toward_the_torque_limit(bus: VirtualBus) -> None:
    motor = bus.motor(2)
    motor.table.set_si("torque_limit", 50.0)
    motor.table.set("torque_enable", 1)
    hand = bus.hand
    hand.move(2, 2.0)  # a small push: a small part of the torque limit
    small = load(bus, 2)
    assert -50.0 < small < 0.0
    hand.move(2, 60.0, over_s=0.2)
    assert hand.wait(10.0)
    assert hand.where()[2] == pytest.approx(0.0, abs=0.3)  # at its goal, not the hand's 60°
    assert load(bus, 2) == pytest.approx(-50.0, abs=0.2)  # the whole torque limit, resisting
    hand.move(2, -60.0)
    assert load(bus, 2) == pytest.approx(50.0, abs=0.2)
    hand.release(2)
    assert load(bus, 2) == 0.0 and hand.where()[2] == pytest.approx(0.0, abs=0.3)


def test_the_hand_is_read_over_the_bus(bus: VirtualBus) -> None:
    model = bus.motor(3).model
    with serve_link(bus) as server, DxlBus(server.url, protocol=2) as client:
        bus.hand.move(3, -25.0, over_s=0.3)

        def present() -> float:
            return float(client.read_register(3, model, "present_position"))

        assert eventually(lambda: abs(present() + 25.0) < 0.5)
        assert client.read_register(3, model, "goal_position") == 0.0


def test_play_moves_through_timed_positions_then_holds(bus: VirtualBus) -> None:
    hand = bus.hand
    duration = hand.play([0.0, 0.5, 1.0], {1: [0.0, 30.0, 10.0], 2: [0.0, -20.0, -20.0]}, 0.5)
    assert duration == 2.0  # at half speed
    seen: list[float] = []
    assert eventually(lambda: seen.append(hand.where()[1]) or not hand.busy())
    assert max(seen) > 15.0  # went up toward 30 before coming back
    assert hand.holding() == pytest.approx({1: 10.0, 2: -20.0})
    assert hand.where()[1] == pytest.approx(10.0, abs=0.3)


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda h: h.move(9, 10.0), "no motor 9 (motors: 1, 2, 3)"),
        (lambda h: h.move(1, float("nan")), "degrees must be a finite number"),
        (lambda h: h.move(1, 10.0, over_s=-1.0), "a gesture lasts 0-3600 s"),
        (lambda h: h.move(1, 10.0, profile="cubic"), "unknown profile 'cubic'"),
        (lambda h: h.play([0.0, 1.0], {1: [0.0]}), "one finite angle per frame"),
        (lambda h: h.play([1.0, 0.0], {1: [0.0, 1.0]}), "increasing times"),
        (lambda h: h.play([0.0], {1: [0.0]}, 0.0), "speed must be positive"),
    ],
)
def test_bad_gestures_are_refused(bus: VirtualBus, call: object, message: str) -> None:
    with pytest.raises((KeyError, ArgumentError), match=re.escape(message)):
        call(bus.hand)  # type: ignore[operator]
    assert not bus.hand.busy()
