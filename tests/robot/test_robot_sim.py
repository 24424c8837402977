"""A simulated Ergo Jr through a real pty: compliance, gotos, speed control, faults, closing."""

from __future__ import annotations

import threading
import time

import pytest

from poppy_core import from_profile
from poppy_core.errors import ConfigError, RobotClosedError
from poppy_core.robot import Robot
from poppy_core.trajectory import MinimumJerk
from tests.helpers import eventually
from tests.helpers.fixtures import ergo_fixture
from tests.helpers.waiting import load_factor

CONTROLLER = "my_dxl_controller"


ergo = ergo_fixture()


def virtual(robot: Robot, motor_id: int):  # type: ignore[no-untyped-def]
    return robot.emulators[CONTROLLER].bus.motor(motor_id)


def test_motors_and_groups_as_attributes(ergo: Robot) -> None:
    assert [m.name for m in ergo.motors] == ["m1", "m2", "m3", "m4", "m5", "m6"]
    assert ergo.base == [ergo.m1, ergo.m2, ergo.m3]
    assert ergo.motor("m4") is ergo.m4 and ergo.group("tip")[0] is ergo.m4
    with pytest.raises(AttributeError):
        _ = ergo.m9
    with pytest.raises(ConfigError):
        ergo.motor("m9")


def test_stiff_motor_reaches_its_goal(ergo: Robot) -> None:
    ergo.m2.compliant = False
    ergo.m2.goal_position = 40  # indirect: the virtual horn goes to -40
    assert eventually(lambda: abs(ergo.m2.present_position - 40) < 1)
    assert virtual(ergo, 2).present_position_deg == pytest.approx(-40, abs=1)
    ergo.m2.goal_position = 500  # clamped to the limit: [-90, 125] in the motor frame, 90 here
    assert eventually(lambda: abs(ergo.m2.present_position - 90) < 1)
    ergo.compliant = True
    assert eventually(lambda: not virtual(ergo, 2).torque_enabled)
    assert ergo.compliant


def test_compliant_motor_follows_the_hand(ergo: Robot) -> None:
    virtual(ergo, 1).move_by_hand(33.0)
    assert eventually(lambda: abs(ergo.m1.present_position - 33) < 0.5)
    virtual(ergo, 1).move_by_hand(170.0)  # past its limits, dummy compliance: stays there
    assert eventually(lambda: ergo.m1.present_position > 140)
    time.sleep(0.1)
    assert not virtual(ergo, 1).torque_enabled


def test_safe_compliance_stiffens_at_the_limit(ergo: Robot) -> None:
    motor = ergo.m3  # indirect, limits -90..90
    motor.compliant_behavior = "safe"
    motor.compliant = True
    virtual(ergo, 3).move_by_hand(-20.0)  # user +20: inside, stays free
    assert eventually(lambda: abs(motor.present_position - 20) < 0.5)
    assert not virtual(ergo, 3).torque_enabled
    virtual(ergo, 3).move_by_hand(-120.0)  # user +120: past the 90° limit
    assert eventually(lambda: virtual(ergo, 3).torque_enabled)
    assert eventually(lambda: abs(motor.present_position - 90) < 1)
    assert motor.compliant and motor.torque_enabled


def test_minjerk_goto_timing_and_accuracy(ergo: Robot) -> None:
    ergo.power_up()
    start = time.monotonic()
    handle = ergo.goto_position({"m1": 60, "m2": -30, "m6": 200}, 1.0)
    assert not handle.done
    time.sleep(0.5)
    before = time.monotonic() - start
    position = ergo.m1.present_position
    after = time.monotonic() - start
    # on the bell between the instants around the read (a read may be a sync period old): about
    # half-way at 0.5 s on an idle machine, later where the sleep overran
    bell = MinimumJerk(0.0, 60.0, 1.0)
    assert bell.position(before - 0.1) - 2 <= position <= bell.position(after) + 2
    assert eventually(lambda: handle.done)  # how long it took: `python -m bench timing`
    assert eventually(lambda: abs(ergo.m1.present_position - 60) < 1, 1.0)
    assert eventually(lambda: abs(ergo.m2.present_position + 30) < 1)
    # clamped: [-110, 90] motor frame, indirect
    assert eventually(lambda: abs(ergo.m6.present_position - 110) < 1)


def test_dummy_goto_and_cancel(ergo: Robot) -> None:
    ergo.power_up()
    first = ergo.m4.goto_position(50, 2.0)
    ergo.m4.goto_position(-20, 0.5, control="dummy", wait=True)
    assert first.done and first.cancelled
    assert ergo.m4.moving_speed == pytest.approx(40, rel=0.1)  # 20° in 0.5 s
    assert eventually(lambda: abs(ergo.m4.present_position + 20) < 1, 1.0)
    with pytest.raises(ValueError):
        ergo.m4.goto_position(0, 1, control="linear")


def test_goal_speed_moves_at_speed_and_stops_at_the_limit(ergo: Robot) -> None:
    ergo.power_up()
    motor = ergo.m5  # indirect, limits -90..90
    motor.goal_speed = 100
    time.sleep(0.1)
    p0, t0 = motor.present_position, time.monotonic()
    time.sleep(0.3)
    speed = (motor.present_position - p0) / (time.monotonic() - t0)
    assert 50 < speed < 150
    assert motor.present_speed > 0
    assert eventually(lambda: abs(motor.present_position - 90) < 1, 2.0)
    motor.goal_speed = -400
    assert eventually(lambda: abs(motor.present_position + 90) < 1, 2.0)


def test_unplugged_motor_does_not_slow_the_others(ergo: Robot) -> None:
    emulator = ergo.emulators[CONTROLLER].bus
    emulator.unplug(4)
    assert eventually(lambda: not ergo.m4.online, 2.0)
    time.sleep(1.2)  # a full rate window without m4
    stats = ergo.sync_stats()[CONTROLLER]
    assert "m4" in stats.offline and stats.motor_errors["m4"] >= 3
    # the rate itself is the soak bench's (`python -m bench soak` unplugs motors in turn): here
    # the loop keeps its pace but for the load (at 4 busy loops it ran at 10.6 Hz, m4 or not)
    assert stats.loops["present"].measured_hz > 30 / load_factor()
    virtual(ergo, 1).move_by_hand(-25.0)
    assert eventually(lambda: abs(ergo.m1.present_position + 25) < 0.5, 1.0)
    emulator.plug(4)
    assert eventually(lambda: ergo.m4.online, 3.0)
    assert ergo.sync_stats()[CONTROLLER].offline == []


def test_to_config_reflects_the_motors(ergo: Robot) -> None:
    ergo.m1.angle_limit = (-100, 100)
    config = ergo.to_robot_config()
    assert config.motors["m1"].angle_limit == (-100, 100)
    assert config.controllers[CONTROLLER].port == "auto"
    assert ergo.to_config()["motors"]["m1"]["angle_limit"] == [-100, 100]
    assert eventually(
        lambda: virtual(ergo, 1).table.get_si("max_position_limit") == pytest.approx(100, abs=0.3),
        2.0,
    )
    ergo.m2.angle_limit = (-120, 80)  # user frame; m2 is indirect
    assert ergo.to_robot_config().motors["m2"].angle_limit == (-80, 120)  # configs: motor frame
    assert eventually(
        lambda: virtual(ergo, 2).table.get_si("max_position_limit") == pytest.approx(120, abs=0.3),
        2.0,
    )


def test_close_stops_every_thread() -> None:
    before = set(threading.enumerate())
    robot = from_profile("ergo-jr", sim=True)
    robot.power_up()
    robot.goto_position({"m1": 40}, 5.0)
    assert len(set(threading.enumerate()) - before) >= 2  # sync, goto (the emulator runs in them)
    robot.m1.compliant = True
    robot.close()
    robot.close()
    assert set(threading.enumerate()) - before == set()
    assert robot.closed
    with pytest.raises(RobotClosedError):
        robot.goto_position({"m1": 0}, 1.0)


def test_context_manager_sends_last_orders() -> None:
    with from_profile("ergo-jr", sim=True) as robot:
        robot.power_up()
        time.sleep(0.1)
        bus = robot.emulators[CONTROLLER].bus
        robot.compliant = True  # sent by the final flush even if the loop is not due yet
        assert robot.m1.compliant
    assert not any(m.torque_enabled for m in bus.motors)
