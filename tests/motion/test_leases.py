"""The lease registry alone: one owner per motor, a strict take refused, a plain one taking only
the free motors, leases that lapse (owner done, owner silent), primitives read from the manager."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from poppy_core import from_profile
from poppy_core.errors import MotorLeasedError
from poppy_core.motion import Sinus
from poppy_core.motion.leases import Lease, MotorLeases, motor_leases
from poppy_core.robot import Robot
from tests.helpers.waiting import eventually


@pytest.fixture
def robot() -> Iterator[Robot]:
    with from_profile("ergo-jr", sim=True) as built:
        yield built


def test_one_registry_per_robot(robot: Robot) -> None:
    assert motor_leases(robot) is motor_leases(robot)


def test_a_strict_take_is_refused_and_a_plain_one_takes_the_free_motors(robot: Robot) -> None:
    leases = MotorLeases(robot)
    teleop = Lease("teleop", client="192.168.1.20", stop="teleop.stop")
    assert leases.take(teleop, ["m2"]) == ["m2"]
    move = Lease("move", "wave", "127.0.0.1")
    with pytest.raises(MotorLeasedError) as refused:
        leases.take(move, ["m1", "m2"])
    assert str(refused.value) == (
        "m2 is driven by teleop from 192.168.1.20: stop it first (teleop.stop)"
    )
    assert refused.value.motors == ["m2"] and refused.value.owner == "teleop from 192.168.1.20"
    assert leases.labels() == {"m2": "teleop from 192.168.1.20"}  # nothing taken
    assert leases.take(move, ["m1", "m2"], strict=False) == ["m1"]
    assert leases.labels() == {"m1": "move wave from 127.0.0.1", "m2": "teleop from 192.168.1.20"}
    with pytest.raises(MotorLeasedError) as both:
        leases.check(["m1", "m2"], writer="v1")
    assert str(both.value) == (
        "m1 is driven by move wave from 127.0.0.1: stop it first (POST /api/v1/web/stop); "
        "m2 is driven by teleop from 192.168.1.20: stop it first (teleop.stop)"
    )
    leases.check(["m2"], writer=teleop.holder)  # the owner's own goals pass
    leases.check(["m3"], writer="v1")
    assert set(leases.release_all()) == {teleop, move}
    assert leases.labels() == {}


def test_the_same_holder_takes_its_motors_again(robot: Robot) -> None:
    leases = MotorLeases(robot)
    first = Lease("trajectory", client="ROS 2", holder="ROS 2")
    leases.take(first, ["m1"])
    second = Lease("trajectory", client="ROS 2", holder="ROS 2")
    assert leases.take(second, ["m1", "m2"]) == ["m1", "m2"]
    leases.release_holder("ROS 2")
    assert leases.owners() == {}


def test_a_lease_lapses_when_its_owner_is_done_or_silent(robot: Robot) -> None:
    leases = MotorLeases(robot)
    done = [False]
    leases.take(Lease("move", "wave", alive=lambda: not done[0]), ["m1"])
    stream = Lease("goal stream", client="zenoh:x", lapse_s=0.2)
    leases.take(stream, ["m2"])
    assert set(leases.labels()) == {"m1", "m2"}
    done[0] = True
    assert set(leases.labels()) == {"m2"}
    assert eventually(lambda: leases.labels() == {})
    stream.touch()  # heard again: live again, but its motors were freed
    assert leases.labels() == {}


def test_a_running_primitive_owns_the_motors_it_asks_goals_of(robot: Robot) -> None:
    leases = MotorLeases(robot)
    sinus = Sinus(robot, 50.0, [robot.m3], amp=10.0, freq=0.5)
    sinus.start()
    try:
        assert eventually(lambda: leases.labels() == {"m3": "primitive sinus"})
        with pytest.raises(MotorLeasedError, match="/api/v1/primitives/sinus/stop"):
            leases.take(Lease("teleop", client="a"), ["m3"])
        # primitives are pypot's: their goals are combined by the manager, never refused
        other = Sinus(robot, 50.0, [robot.m3], amp=5.0, freq=1.0)
        other.start()
        other.stop()
    finally:
        sinus.stop()
    assert eventually(lambda: leases.labels() == {})
