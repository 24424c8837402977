"""Built-in primitives: signals of Sinus/Cosinus/Square, SimplePosture, PositionWatcher's plot."""

from __future__ import annotations

import math
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from poppy_core import from_profile
from poppy_core.motion import (
    BUILTINS,
    Cosinus,
    PositionWatcher,
    SimplePosture,
    Sinus,
    Square,
    attach_builtins,
)
from poppy_core.robot import Robot
from tests.helpers.fixtures import ergo_fixture

ergo = ergo_fixture()


@pytest.fixture(scope="module")
def shared() -> Iterator[Robot]:
    robot = from_profile("ergo-jr", sim=True)
    try:
        yield robot
    finally:
        robot.close()


def test_sinus_and_cosinus_signals(shared: Robot) -> None:
    sinus = Sinus(shared, 50, ["m1"], amp=10, freq=1, offset=5, phase=0)
    cosinus = Cosinus(shared, 50, ["m1"], amp=10, freq=1, offset=5, phase=0)
    assert sinus.signal(0.0) == pytest.approx(5.0)
    assert sinus.signal(0.25) == pytest.approx(15.0)
    assert cosinus.signal(0.0) == pytest.approx(15.0)
    sinus.phase = 90.0
    assert sinus.signal(0.0) == pytest.approx(cosinus.signal(0.0))


@given(t=st.floats(0, 100), duty=st.floats(0, 1), amp=st.floats(0, 90), offset=st.floats(-45, 45))
def test_square_takes_two_values(
    shared: Robot, t: float, duty: float, amp: float, offset: float
) -> None:
    square = Square(shared, 50, ["m1"], amp=amp, freq=1.0, offset=offset, duty=duty)
    assert square.signal(t) in (offset + amp, offset - amp)


def test_square_duty_cycle(shared: Robot) -> None:
    square = Square(shared, 50, ["m1"], amp=10, freq=1.0, duty=0.25)
    assert square.signal(0.1) == 10.0
    assert square.signal(0.3) == -10.0
    assert square.signal(1.2) == 10.0
    with pytest.raises(ValueError):
        square.duty = 1.5


def test_defaults_use_every_motor(shared: Robot) -> None:
    names = [m.name for m in shared.motors]
    assert Sinus(shared).motor_list == names
    assert PositionWatcher(shared).watched_motors == names
    assert set(SimplePosture(shared).target_position) == set(names)
    assert Sinus(shared, 50, [shared.m2]).motor_list == ["m2"]


def test_simple_posture_reaches_its_target(ergo: Robot) -> None:
    posture = SimplePosture(ergo, 0.4, {"m2": 30.0, "m3": -20.0})
    start = time.monotonic()
    posture.go(wait=True)
    assert time.monotonic() - start >= 0.35
    assert posture.state == "stopped"
    assert not ergo.m2.compliant  # its setup stiffened the motors it moves
    deadline = time.monotonic() + 2.0
    while time.monotonic() < deadline and abs(ergo.m2.present_position - 30.0) > 2.0:
        time.sleep(0.02)
    assert abs(ergo.m2.present_position - 30.0) <= 2.0
    assert abs(ergo.m3.goal_position + 20.0) <= 0.5


def test_position_watcher_records_and_plots(ergo: Robot, tmp_path: Path) -> None:
    watcher = PositionWatcher(ergo, 50, ["m1", "m2"])
    ergo.compliant = False
    ergo.goto_position({"m1": 20.0}, 0.3)
    watcher.start()
    time.sleep(0.4)
    watcher.stop()
    samples = len(watcher.times)
    assert samples >= 5
    assert {len(v) for v in watcher.record_positions.values()} == {samples}
    assert watcher.times == sorted(watcher.times)
    assert all(math.isfinite(p) for p in watcher.record_positions["m1"])
    out = watcher.call_method("plot", tmp_path / "positions.png")
    data = Path(out).read_bytes()
    assert data.startswith(b"\x89PNG\r\n\x1a\n") and len(data) > 1000
    from matplotlib.figure import Figure

    ax = Figure().add_subplot()
    assert watcher.plot(ax) is ax  # pypot's call: draw on the caller's axis
    assert sorted(line.get_label() for line in ax.get_lines()) == ["m1", "m2"]
    assert len(ax.get_lines()[0].get_xdata()) == samples


def test_attach_builtins(ergo: Robot) -> None:
    attached = attach_builtins(ergo)
    assert list(attached) == list(BUILTINS)
    assert ergo.sinus is attached["sinus"]
    assert isinstance(ergo.position_watcher, PositionWatcher)
    again = attach_builtins(ergo)  # idempotent: the same instances
    assert again == attached
    for primitive in attached.values():
        assert primitive.describe()["state"] == "idle"
