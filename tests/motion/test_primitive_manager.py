"""The sandbox and the manager: requests, their combination (mean, sum, any function), writes."""

from __future__ import annotations

import logging
import time

import pytest

from poppy_core import from_profile
from poppy_core.errors import (
    ArgumentError,
    PrimitiveError,
    RegisterError,
    UnknownMotorError,
)
from poppy_core.motion import (
    FILTERS,
    LoopPrimitive,
    MockupMotor,
    MockupRobot,
    PrimitiveManager,
    Sinus,
    primitive_manager,
)
from poppy_core.robot import Robot
from tests.helpers import eventually
from tests.helpers.fixtures import ergo_fixture

ergo = ergo_fixture(stiff=True, creature=False)  # no Ergo Jr primitives


def constant(robot: Robot, motor: str, value: float) -> Sinus:
    """A Sinus of zero frequency: a constant request ``value`` on ``motor``."""
    return Sinus(robot, 50, [motor], amp=0.0, freq=0.0, offset=value)


def test_mockup_writes_are_requests_and_reads_pass_through(ergo: Robot) -> None:
    real = ergo.m1
    mock = MockupMotor(real)
    before = real.goal_position
    mock.goal_position = 42.0
    mock.led = "red"
    mock.compliant = True
    assert mock.goal_position == 42.0  # a primitive reads back its own request
    assert real.goal_position == before  # the real motor is untouched
    assert mock.present_position == real.present_position
    assert mock.angle_limit == real.angle_limit
    assert mock.requests() == {"goal_position": 42.0, "led": "red", "compliant": True}
    mock.clear()
    assert mock.requests() == {}
    assert mock.real_motor is real


def test_mockup_refuses_what_a_primitive_may_not_do(ergo: Robot) -> None:
    mock = MockupMotor(ergo.m1)
    with pytest.raises(RegisterError, match="may request only"):
        mock.angle_limit = (-10.0, 10.0)
    with pytest.raises(RegisterError, match="number"):
        mock.goal_position = "far"  # type: ignore[assignment]
    with pytest.raises(RegisterError, match="magnitude"):
        mock.moving_speed = -5
    with pytest.raises(RegisterError):
        mock.led = "ultraviolet"
    with pytest.raises(RegisterError, match="finite"):
        mock.goal_position = float("inf")


def test_mockup_goto_samples_a_trajectory(ergo: Robot) -> None:
    mock = MockupMotor(ergo.m1)
    mock.goal_position = 0.0
    mock.goto_position(40.0, 1.0)
    requested = mock.requests()
    assert requested["moving_speed"] == 0.0
    assert 0.0 <= requested["goal_position"] < 40.0
    t0 = time.monotonic()
    assert mock.requests(t0 + 0.5)["goal_position"] == pytest.approx(20.0, abs=2.0)
    assert mock.requests(t0 + 5.0)["goal_position"] == pytest.approx(40.0)
    mock.goto_position(10.0, 0.5, control="dummy")
    assert mock.requests()["goal_position"] == 10.0
    with pytest.raises(ValueError):
        mock.goto_position(10.0, 1.0, control="teleport")


def test_mockup_dummy_goto_slower_than_a_step_is_not_full_speed(ergo: Robot) -> None:
    """The one goto plan (``plan_goto``) floors a dummy speed at one register step for
    primitives too: a moving speed of 0 would send the servo at full speed."""
    mock = MockupMotor(ergo.m1)
    mock.goal_position = 0.0
    mock.goto_position(0.001, 1000.0, control="dummy")
    step = abs(float(ergo.m1.model.register("moving_speed").to_si(1)))
    assert step > 0
    assert mock.requests() == {"moving_speed": pytest.approx(step), "goal_position": 0.001}


def test_mockup_goal_speed_heads_for_the_limit(ergo: Robot) -> None:
    mock = MockupMotor(ergo.m1)
    mock.goal_speed = 30.0
    low, high = ergo.m1.angle_limit
    assert mock.requests() == {"moving_speed": 30.0, "goal_position": high}
    mock.goal_speed = -30.0
    assert mock.requests()["goal_position"] == low


def test_mockup_robot_groups_and_passthrough(ergo: Robot) -> None:
    sandbox = MockupRobot(ergo)
    assert [m.name for m in sandbox.motors] == [m.name for m in ergo.motors]
    assert isinstance(sandbox.m1, MockupMotor)
    for name, members in ergo.motorgroups.items():
        assert [m.name for m in getattr(sandbox, name)] == [m.name for m in members]
    assert sandbox.config is ergo.config  # everything else reads the real robot
    sandbox.compliant = True
    assert all(v == {"compliant": True} for v in sandbox.requests().values())
    assert not ergo.compliant  # still only requests
    with pytest.raises(UnknownMotorError, match="no motor"):
        sandbox.motor("m9")


def test_two_sinus_combine_by_mean(ergo: Robot) -> None:
    first, second = constant(ergo, "m1", 10.0), constant(ergo, "m1", 30.0)
    first.start()
    second.start()
    manager = primitive_manager(ergo)
    assert eventually(lambda: len(manager.primitives) == 2)
    assert eventually(lambda: manager.combine()["m1"]["goal_position"] == pytest.approx(20.0))
    assert eventually(lambda: abs(ergo.m1.goal_position - 20.0) < 0.5)
    assert eventually(lambda: abs(ergo.m1.present_position - 20.0) < 2.0)
    first.stop()
    second.stop()
    assert eventually(lambda: not manager.running)


def test_two_sinus_combine_by_sum(ergo: Robot) -> None:
    manager = primitive_manager(ergo)
    manager.filter = "sum"
    assert manager.filter is FILTERS["sum"]
    first, second = constant(ergo, "m1", 10.0), constant(ergo, "m1", 15.0)
    first.start()
    second.start()
    assert eventually(lambda: abs(ergo.m1.goal_position - 25.0) < 0.5)
    manager.filter = max  # any function of the list of requests
    assert eventually(lambda: abs(ergo.m1.goal_position - 15.0) < 0.5)
    first.stop()
    second.stop()
    with pytest.raises(ArgumentError, match="unknown filter"):
        manager.filter = "median-ish"


def test_real_sinus_moves_the_motor(ergo: Robot) -> None:
    sinus = Sinus(ergo, 50, ["m1"], amp=20.0, freq=1.0)
    sinus.start()
    seen: list[float] = []
    deadline = time.monotonic() + 1.2
    while time.monotonic() < deadline:
        seen.append(ergo.m1.goal_position)
        time.sleep(0.02)
    sinus.stop()
    assert max(seen) > 15.0 and min(seen) < -15.0


def test_last_request_is_applied_when_a_primitive_ends(ergo: Robot) -> None:
    posture = constant(ergo, "m3", -12.0)
    posture.start()
    posture.stop()
    assert abs(ergo.m3.goal_position + 12.0) < 0.5 or eventually(
        lambda: abs(ergo.m3.goal_position + 12.0) < 0.5
    )


def test_on_off_registers_follow_the_latest_primitive(ergo: Robot) -> None:
    manager = PrimitiveManager(ergo)
    first, second = constant(ergo, "m1", 0.0), constant(ergo, "m1", 0.0)
    first.robot.m1.compliant = True
    second.robot.m1.compliant = False
    manager.add(first)
    manager.add(second)
    assert manager.combine()["m1"]["compliant"] is False
    manager.close()


def test_bad_filter_result_is_counted_not_applied(ergo: Robot) -> None:
    manager = PrimitiveManager(ergo, filter=lambda values: float("nan"))
    sinus = constant(ergo, "m1", 5.0)
    sinus.robot.m1.goal_position = 5.0
    manager.add(sinus)
    manager.update()
    assert manager.errors >= 1 and manager.last_error is not None
    manager.close()
    with pytest.raises(ArgumentError, match="manager frequency"):
        PrimitiveManager(ergo, freq=0)


class Mirror(LoopPrimitive):
    """Writes a goal to ``head_z``, a motor the robot does not have: its sandbox is another
    robot's (a primitive pointed at the wrong robot)."""

    def __init__(self, robot: Robot, other: Robot) -> None:
        super().__init__(robot, 50)
        self.robot = MockupRobot(other, self._stop_event)

    def update(self) -> None:
        self.robot.head_z.goal_position = 5.0


def test_a_primitive_requesting_an_unknown_motor_is_stopped_and_the_manager_goes_on(
    ergo: Robot, caplog: pytest.LogCaptureFixture
) -> None:
    manager = primitive_manager(ergo)
    with from_profile("torso", sim=True, creature=False) as torso:
        before = constant(ergo, "m2", 15.0)
        before.start()
        assert eventually(lambda: abs(ergo.m2.goal_position - 15.0) < 0.5)
        stray = Mirror(ergo, torso)
        with caplog.at_level(logging.WARNING):
            stray.start()
            assert eventually(lambda: stray.state == "failed" and not stray.is_alive())
            assert stray.error is not None and stray.error.type == "UnknownMotorError"
            assert "'head_z'" in stray.error.message and "\n" not in stray.error.one_line
            assert stray.describe()["error"]["type"] == "UnknownMotorError"
            after = constant(ergo, "m3", -12.0)  # the manager still combines requests
            after.start()
            assert eventually(lambda: abs(ergo.m3.goal_position + 12.0) < 0.5)
            assert manager.running and stray not in manager.primitives
            assert manager.last_error is not None and "head_z" in manager.last_error
            with pytest.raises(PrimitiveError, match=r"UnknownMotorError: .*'head_z'"):
                stray.stop()
            before.stop()
            after.stop()
        warned = [r for r in caplog.records if "head_z" in r.getMessage()]
        assert len(warned) == 1 and warned[0].levelno == logging.WARNING
        assert "\n" not in warned[0].getMessage()
        assert before.error is None and after.error is None
    assert eventually(lambda: not manager.running)


class _Refusing:
    """A motor that refuses every write while ``refusing`` is set."""

    refusing = True

    def __setattr__(self, name: str, value: object) -> None:
        if type(self).refusing:
            raise ValueError(f"{name} refused")


def test_a_refused_write_is_logged_once_until_it_is_taken_again(
    ergo: Robot, caplog: pytest.LogCaptureFixture, monkeypatch: pytest.MonkeyPatch
) -> None:
    manager = PrimitiveManager(ergo)
    posture = constant(ergo, "m1", 5.0)
    posture.robot.m1.goal_position = 5.0
    manager.add(posture)
    refusing = _Refusing()
    monkeypatch.setattr(ergo, "motor", lambda name: refusing)
    with caplog.at_level(logging.WARNING, logger="poppy_core.motion.manager"):
        for _ in range(5):
            manager.update()
        _Refusing.refusing = False
        manager.update()  # taken: the next refusal is news again
        _Refusing.refusing = True
        posture.robot.m1.goal_position = 6.0
        manager.update()
        manager.update()
    refused = [r for r in caplog.records if "m1.goal_position" in r.getMessage()]
    assert [r.levelno for r in refused] == [logging.WARNING, logging.WARNING]
    assert all("\n" not in r.getMessage() for r in refused)
    assert manager.errors >= 7  # the manager's own loop may update too
    manager.close()


def test_a_combination_that_raises_is_logged_once_and_the_manager_goes_on(
    ergo: Robot, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    """The manager's thread lives through a raising combination (logged once, counted in
    ``errors``, retried with backoff) and applies the requests again once it passes."""
    manager = primitive_manager(ergo)
    real = manager.update
    failing = [True]

    def flaky() -> None:
        if failing[0]:
            raise RuntimeError("combination broke")
        real()

    monkeypatch.setattr(manager, "update", flaky)
    caplog.set_level(logging.WARNING, logger="poppy_core.schedule")
    hold = constant(ergo, "m1", 20.0)
    hold.start()
    try:
        assert eventually(lambda: manager.errors >= 3)
        assert manager.running and "combination broke" in str(manager.last_error)
        failing[0] = False
        assert eventually(lambda: ergo.m1.goal_position == pytest.approx(20, abs=0.5))
    finally:
        hold.stop()
    warned = [r for r in caplog.records if "a tick failed" in r.getMessage()]
    assert len(warned) == 1 and "primitive manager" in warned[0].getMessage()
