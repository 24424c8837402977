"""Primitives on a simulated Ergo Jr: lifecycle, timing, failures, properties and attaching."""

from __future__ import annotations

import logging
import threading
import time

import pytest

from poppy_core import from_profile
from poppy_core.errors import ArgumentError, ConfigError, PrimitiveError, RobotClosedError
from poppy_core.motion import (
    LoopPrimitive,
    Primitive,
    SimplePosture,
    Sinus,
    active_primitives,
    attach_primitive,
    attached_primitives,
    primitive_manager,
)
from poppy_core.robot import Robot
from tests.helpers import eventually
from tests.helpers.fixtures import ergo_fixture


def state(primitive: Primitive) -> str:
    """The state, read afresh (keeps mypy from narrowing it between two reads)."""
    return primitive.state


ergo = ergo_fixture(creature=False)  # no Ergo Jr primitives


class Counter(Primitive):
    """Counts its loops until stopped; honours pause."""

    def __init__(self, robot: Robot) -> None:
        super().__init__(robot)
        self.count = 0
        self.setups = 0
        self.teardowns = 0

    def setup(self) -> None:
        self.setups += 1

    def run(self) -> None:
        while not self.should_stop():
            if self.should_pause():
                self.wait_to_resume()
                continue
            self.count += 1
            self.sleep(0.005)

    def teardown(self) -> None:
        self.teardowns += 1


class Ticker(LoopPrimitive):
    """Counts its updates."""

    def __init__(self, robot: Robot, freq: float) -> None:
        super().__init__(robot, freq)
        self.updates = 0

    def update(self) -> None:
        self.updates += 1


class Crasher(LoopPrimitive):
    """Raises on its third update."""

    def __init__(self, robot: Robot) -> None:
        super().__init__(robot, 50)
        self.updates = 0

    def setup(self) -> None:
        self.updates = 0

    def update(self) -> None:
        self.updates += 1
        self.robot.m1.goal_position = 40.0
        if self.updates == 3:
            raise ValueError("boom at update 3")


def test_start_stop_restart(ergo: Robot) -> None:
    counter = Counter(ergo)
    assert state(counter) == "idle" and not counter.is_alive()
    counter.start()
    assert state(counter) == "running" and counter.is_alive()
    assert eventually(lambda: counter.count > 3)
    counter.stop()
    assert state(counter) == "stopped" and not counter.is_alive()
    assert (counter.setups, counter.teardowns) == (1, 1)
    counted = counter.count
    time.sleep(0.05)
    assert counter.count == counted
    counter.start()  # restartable, unlike a plain thread
    assert state(counter) == "running"
    assert eventually(lambda: counter.count > counted)
    counter.start()  # start while running restarts it
    assert (counter.setups, counter.teardowns) == (3, 2)
    counter.stop()
    assert counter.wait_to_stop(1.0)
    assert counter.error is None


def test_pause_and_resume(ergo: Robot) -> None:
    counter = Counter(ergo)
    counter.start()
    assert eventually(lambda: counter.count > 0)
    counter.pause()
    assert state(counter) == "paused" and counter.should_pause()
    assert counter.is_alive()  # paused is alive
    time.sleep(0.05)
    frozen = counter.count
    time.sleep(0.1)
    assert counter.count == frozen
    counter.resume()
    assert state(counter) == "running"
    assert eventually(lambda: counter.count > frozen)
    counter.stop()
    assert not counter.is_alive()


def test_stop_a_paused_primitive(ergo: Robot) -> None:
    counter = Counter(ergo)
    counter.start()
    counter.pause()
    counter.stop()
    assert state(counter) == "stopped" and not counter.is_alive()


def test_elapsed_time(ergo: Robot) -> None:
    counter = Counter(ergo)
    assert counter.elapsed_time == 0.0
    counter.start()
    time.sleep(0.3)
    assert 0.25 <= counter.elapsed_time < 2.0
    counter.pause()
    paused_at = counter.elapsed_time
    time.sleep(0.2)
    assert counter.elapsed_time - paused_at < 0.1  # pauses do not count
    counter.stop()
    final = counter.elapsed_time
    time.sleep(0.05)
    assert counter.elapsed_time == final  # frozen once stopped
    counter.start()
    assert counter.elapsed_time < final  # a restart starts from 0
    counter.stop()


def test_loop_primitive_rate(ergo: Robot) -> None:
    ticker = Ticker(ergo, 50)
    ticker.start()
    time.sleep(0.5)
    ticker.stop()
    # 50 Hz for 0.5 s is 25 updates; the schedule never runs ahead of its deadlines.
    assert 12 <= ticker.updates <= 27
    assert 25 <= ticker.update_rate_hz <= 60
    assert ticker.recent_update_frequencies
    with pytest.raises(ValueError):
        ticker.update_freq = 0


def test_crash_is_reported_and_the_manager_survives(
    ergo: Robot, caplog: pytest.LogCaptureFixture
) -> None:
    ergo.compliant = False
    steady = Sinus(ergo, 50, ["m2"], amp=0.0, offset=15.0)
    steady.start()
    crasher = Crasher(ergo)
    with caplog.at_level(logging.WARNING, logger="poppy_core.motion.primitive"):
        crasher.start()
        assert eventually(lambda: not crasher.is_alive())
        with pytest.raises(PrimitiveError, match="boom at update 3") as raised:
            crasher.wait_to_stop(3.0)
    assert isinstance(raised.value.__cause__, ValueError)
    assert state(crasher) == "failed"
    assert not crasher.is_alive()
    assert crasher.error is not None
    assert crasher.error.type == "ValueError"
    assert crasher.error.message == "boom at update 3"
    assert "Traceback" in crasher.error.traceback and "boom at update 3" in crasher.error.traceback
    assert crasher.error.one_line == "ValueError: boom at update 3"
    assert crasher.describe()["error"]["type"] == "ValueError"
    assert any(
        r.name == "poppy_core.motion.primitive" and "boom at update 3" in r.getMessage()
        for r in caplog.records
    )
    manager = primitive_manager(ergo)
    assert crasher not in manager.primitives and steady in manager.primitives
    # The manager still applies the other primitive's requests.
    steady.set_property("offset", -20)
    assert eventually(lambda: abs(ergo.m2.goal_position + 20) < 1)
    assert manager.running
    steady.stop()
    first_error = crasher.error
    crasher.start()  # a failed primitive can be started again (its error is reset)
    assert eventually(lambda: not crasher.is_alive())
    crasher.halt()  # a supervisor stops it without raising
    assert state(crasher) == "failed" and crasher.updates == 3
    assert crasher.error is not None and crasher.error is not first_error


class _BadSetup(Primitive):
    ran = False

    def setup(self) -> None:
        self.real_robot.motor("nope")

    def run(self) -> None:
        self.ran = True


def test_failing_setup_never_runs(ergo: Robot) -> None:
    primitive = _BadSetup(ergo)
    primitive.start()
    with pytest.raises(PrimitiveError, match="UnknownMotorError"):
        primitive.wait_to_stop(3.0)
    assert state(primitive) == "failed"
    assert not primitive.ran
    assert primitive.error is not None and primitive.error.type == "UnknownMotorError"
    assert "nope" in primitive.error.message


def test_properties_get_set_and_validation(ergo: Robot) -> None:
    sinus = Sinus(ergo, 50, ["m1"], amp=10, freq=0.5)
    assert sinus.get_property("amplitude") == 10.0
    sinus.set_property("amplitude", "20")
    assert sinus.amplitude == 20.0
    sinus.set_property("frequency", 2)
    assert sinus.get_property("frequency") == 2.0
    sinus.set_property("motor_list", "m1, m2")
    assert sinus.motor_list == ["m1", "m2"]
    with pytest.raises(ArgumentError, match="not a number"):
        sinus.set_property("amplitude", "loud")
    with pytest.raises(ArgumentError, match="not a number"):
        sinus.set_property("amplitude", True)
    with pytest.raises(ArgumentError, match="finite"):
        sinus.set_property("offset", "nan")
    with pytest.raises(ArgumentError, match="frequency"):
        sinus.set_property("frequency", -1)
    with pytest.raises(ConfigError, match="no property 'colour'"):
        sinus.set_property("colour", 1)
    with pytest.raises(ConfigError, match="no property"):
        sinus.get_property("run")
    assert set(sinus.property_values()) == set(Sinus.properties)
    posture = SimplePosture(ergo)
    posture.set_property("target_position", "m1=10, m2=-5")
    assert posture.target_position == {"m1": 10.0, "m2": -5.0}
    with pytest.raises(ArgumentError, match="NAME=NUMBER"):
        posture.set_property("target_position", "m1")


def test_call_method(ergo: Robot) -> None:
    sinus = Sinus(ergo, 50, ["m1"])
    sinus.call_method("start")
    assert sinus.is_alive()
    sinus.call_method("stop")
    assert not sinus.is_alive()
    with pytest.raises(ConfigError, match="no method 'run'"):
        sinus.call_method("run")


def test_attach_primitive(ergo: Robot) -> None:
    dance = Sinus(ergo, 50, ["m1"])
    ergo.attach_primitive(dance, "dance")
    assert ergo.dance is dance
    assert ergo.primitives == [dance]
    assert "dance" in dir(ergo)
    watcher = Counter(ergo)
    attach_primitive(ergo, "watch", watcher)
    assert attached_primitives(ergo) == {"dance": dance, "watch": watcher}
    assert ergo.active_primitives == []
    dance.start()
    assert ergo.active_primitives == [dance]
    assert active_primitives(ergo) == [dance]
    dance.stop()
    with pytest.raises(ConfigError):
        attach_primitive(ergo, "m1", Counter(ergo))  # a motor's name
    with pytest.raises(ConfigError):
        attach_primitive(ergo, "close", Counter(ergo))  # a Robot attribute


def test_attach_a_primitive_of_another_robot(ergo: Robot) -> None:
    with (
        from_profile("ergo-jr", sim=True) as other,
        pytest.raises(ConfigError, match="another robot"),
    ):
        attach_primitive(ergo, "foreign", Counter(other))


def test_close_stops_primitives(ergo: Robot) -> None:
    counter = Counter(ergo)
    counter.start()
    manager = primitive_manager(ergo)
    ergo.close()
    assert not counter.is_alive()
    assert not manager.running
    with pytest.raises(RobotClosedError, match="closed"):
        counter.start()
    assert state(counter) == "stopped"


def test_primitive_cannot_restart_itself(ergo: Robot) -> None:
    errors: list[BaseException] = []

    class Selfish(Primitive):
        def run(self) -> None:
            try:
                self.start()
            except RuntimeError as exc:
                errors.append(exc)

    selfish = Selfish(ergo)
    selfish.start()
    assert selfish.wait_to_stop(2.0)
    assert len(errors) == 1 and state(selfish) == "stopped"
    assert threading.active_count() >= 1


class DiesInRun(Primitive):
    """Dies on a name it lacks, as pypot's Switcher did on poppy before affect_once."""

    def run(self) -> None:
        self.sleep(0.05)
        self.no_such_method()  # type: ignore[attr-defined]


def test_a_dead_primitive_says_so_to_whoever_waits(
    ergo: Robot, caplog: pytest.LogCaptureFixture
) -> None:
    primitive = DiesInRun(ergo)
    with caplog.at_level(logging.WARNING, logger="poppy_core.motion.primitive"):
        primitive.start()
        with pytest.raises(PrimitiveError, match="no_such_method") as waited:
            primitive.wait_to_stop()  # no timeout: it must not block for good
        with pytest.raises(PrimitiveError, match="dies_in_run died: AttributeError"):
            primitive.stop()
    assert isinstance(waited.value.__cause__, AttributeError)
    assert waited.value.primitive == "dies_in_run"
    deaths = [r for r in caplog.records if "died" in r.getMessage()]
    assert len(deaths) == 1 and deaths[0].levelno == logging.WARNING
    primitive.halt()  # supervisors (close, the servers) stop it without raising
    ergo.close()  # and closing the robot does not raise either


class _Switcher(LoopPrimitive):
    """pypot's tests/test_primitive.py::test_set_once, in poppy's words."""

    def setup(self) -> None:
        self.state_on = False
        self.old_state = False
        self.switched = threading.Event()

    def update(self) -> None:
        if self.state_on != self.old_state:
            for m in self.robot.motors:
                self.affect_once(m, "led", "red" if self.state_on else "off")
            self.old_state = self.state_on
            self.switched.set()


def test_affect_once_writes_the_real_motor_once(ergo: Robot) -> None:
    switcher = _Switcher(ergo, 10)
    switcher.start()
    assert eventually(lambda: hasattr(switcher, "switched"))
    for m in ergo.motors:
        m.led = "off"
    switcher.state_on = True
    assert switcher.switched.wait(10.0)
    assert [m.led for m in ergo.motors] == ["red"] * 6
    ergo.m3.led = "blue"  # written once: the user's write stays
    time.sleep(0.3)  # three updates of the switcher
    assert [m.led for m in ergo.motors] == ["red", "red", "blue", "red", "red", "red"]
    switcher.stop()
    with pytest.raises(ConfigError):
        switcher.affect_once("m9", "led", "red")
