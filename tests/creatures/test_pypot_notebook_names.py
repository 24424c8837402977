"""pypot names that notebooks still use, each in the call form the notebooks write (issue 23.5).

Replayed notebooks of poppy-ergo-jr, poppy-torso, pypot's samples and the community: a module
version, ``installed_poppy_creatures``, ``XL320LEDColors``, ``move.plot(ax)``,
``poppy.chain.plot(poppy.chain.convert_to_ik_angles(poppy.chain.joints_position), ax)``,
``poppy.tetris_posture``, the Torso's ``init_position`` and ``poppy.snap.run()``.
"""

from __future__ import annotations

import importlib.metadata
import threading
from collections.abc import Iterator
from typing import Any

import httpx
import numpy as np
import pytest

import poppy_core
from poppy_core.bus import XL320LEDColors
from poppy_core.errors import ArgumentError, KinematicsError
from poppy_core.models import XL_320
from poppy_core.motion import Move
from poppy_core.pypot import PoppyErgoJr, PoppyTorso, installed_poppy_creatures
from poppy_core.robot import Robot
from tests.creatures.helpers import wait_until
from tests.helpers.waiting import http_timeout


@pytest.fixture
def plt() -> Iterator[Any]:
    """matplotlib's pyplot on the Agg backend (no display); every figure closed after."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as pyplot

    yield pyplot
    pyplot.close("all")


@pytest.fixture(scope="module")
def poppy() -> Iterator[Robot]:
    """A virtual Ergo Jr built as the notebooks build it."""
    with PoppyErgoJr(simulator="dummy") as robot:
        yield robot


def test_module_versions() -> None:
    # pypot.__version__, poppy_ergo_jr.__version__: one version, the installed distribution's.
    assert poppy_core.__version__ == importlib.metadata.version("poppy")


def test_installed_poppy_creatures() -> None:
    # `from pypot.creatures import installed_poppy_creatures`: package name -> class.
    assert set(installed_poppy_creatures) == {"poppy-ergo-jr", "poppy-torso", "poppy-humanoid"}
    with installed_poppy_creatures["poppy-ergo-jr"](simulator="dummy") as robot:
        assert [m.name for m in robot.motors] == ["m1", "m2", "m3", "m4", "m5", "m6"]


def test_xl320_led_colors(poppy: Robot) -> None:
    # pypot.dynamixel.conversion.XL320LEDColors: each colour is its register code + 1.
    names = [name for _, name in sorted(XL_320.register("led").conversion.names)]  # type: ignore[attr-defined]
    assert [c.name for c in XL320LEDColors] == names
    assert XL320LEDColors(3).name == "green" and XL320LEDColors.red.value - 1 == 1
    for color in XL320LEDColors:
        poppy.m1.led = color.name
        assert poppy.m1.led == color.name
    poppy.m1.led = "off"


def test_move_plot_on_an_axis(plt: Any) -> None:
    move = Move(10.0)
    for i in range(5):
        move.add_position({"m1": [float(i), 0.0], "m2": [-2.0 * i, 0.0]}, i / 10.0)
    _fig, ax = plt.subplots()
    move.plot(ax)
    assert [line.get_label() for line in ax.lines] == ["m1", "m2"]
    assert list(ax.lines[0].get_xdata()) == pytest.approx([0.0, 0.1, 0.2, 0.3, 0.4])
    assert list(ax.lines[1].get_ydata()) == [0.0, -2.0, -4.0, -6.0, -8.0]
    assert len(Move(10.0).plot().lines) == 0  # an empty move draws nothing, on a new axis


def test_chain_plot_as_the_notebooks(poppy: Robot, plt: Any) -> None:
    fig = plt.figure()
    ax = fig.add_subplot(111, projection="3d")
    joints = poppy.chain.joints_position
    ik_angles = poppy.chain.convert_to_ik_angles(joints)
    assert len(ik_angles) == len(joints) + 2 and ik_angles[0] == ik_angles[-1] == 0.0
    assert poppy.chain.convert_from_ik_angles(ik_angles) == pytest.approx(joints)
    poppy.chain.plot(ik_angles, ax)
    (line,) = ax.lines
    xs, ys, zs = line.get_data_3d()
    # The chain drawn from the base through every joint to the tip, where the chain says.
    assert len(xs) == len(joints) + 2
    tip = np.array([xs[-1], ys[-1], zs[-1]])
    assert tip == pytest.approx(poppy.chain.forward(joints)[:3, 3], abs=1e-9)
    flat = plt.figure().add_subplot(111)
    with pytest.raises(ArgumentError, match="projection='3d'"):
        poppy.chain.plot(ik_angles, flat)
    with pytest.raises(KinematicsError, match="joints"):
        poppy.chain.convert_to_ik_angles([0.0, 0.0])


def test_tetris_posture(poppy: Robot) -> None:
    # poppy_ergo_jr's TetrisPosture: m2 -90, m3 90, m5 -90, m6 -90, the LEDs yellow while moving.
    poppy.tetris_posture.start()
    assert wait_until(lambda: {m.led for m in poppy.motors} == {"yellow"}, 10.0)
    poppy.tetris_posture.wait_to_stop()
    expected = {"m1": 0.0, "m2": -90.0, "m3": 90.0, "m4": 0.0, "m5": -90.0, "m6": -90.0}
    assert wait_until(
        lambda: all(abs(poppy.motor(n).present_position - v) < 2.0 for n, v in expected.items()),
        10.0,
    )
    assert {m.led for m in poppy.motors} == {"off"}


def test_torso_init_position() -> None:
    # poppy_torso's InitPosition: stiff, every motor to 0° in 3 s, then bust_y to 4°.
    with PoppyTorso(simulator="dummy") as torso:
        torso.head_z.goal_position = 20
        assert wait_until(lambda: abs(torso.head_z.present_position - 20) < 2, 10.0)
        torso.init_position.start()
        torso.init_position.wait_to_stop()
        assert not torso.compliant
        assert wait_until(lambda: abs(torso.bust_y.present_position - 4.0) < 1.5, 10.0)
        others = [m for m in torso.motors if m.name != "bust_y"]
        assert max(abs(m.present_position) for m in others) < 1.5


def test_snap_run_returns_when_the_server_already_serves() -> None:
    # pypot's notebooks: PoppyErgoJr(use_snap=True); poppy.snap.run() returned at once.
    with PoppyErgoJr(
        simulator="dummy", use_snap=True, snap_port=0, use_http=True, http_port=0
    ) as robot:
        for server, route in ((robot.snap, "/motors/motors"), (robot.http, "/motors/list.json")):
            returned = threading.Event()
            runner = threading.Thread(target=lambda s=server, r=returned: (s.run(), r.set()))
            runner.daemon = True
            runner.start()
            assert returned.wait(10.0), f"{server!r}.run() blocked"
            still_serving = httpx.get(f"{server.url}{route}", timeout=http_timeout(10))
            assert "m1" in still_serving.text


def test_moving_speed_beyond_the_top_is_capped_in_python_and_over_rest() -> None:
    # `m.moving_speed = 10000`: pypot accepted it and capped it to the servo's top speed, in
    # Python and over its REST API; NaN and non-numbers stay refused (the lead's decision).
    with PoppyErgoJr(simulator="dummy", use_http=True, http_port=0) as robot:
        top = 1023 * 0.111 * 6  # XL-320: the register's 1023 steps of 0.111 rpm
        robot.m1.moving_speed = 10000
        assert robot.m1.moving_speed == pytest.approx(top)
        with pytest.raises(ArgumentError, match=r"m1\.moving_speed must be a finite number"):
            robot.m1.moving_speed = float("nan")
        robot.m2.moving_speed = 50
        url = f"{robot.http.url}/motor/m2/register/moving_speed/value.json"
        answer = httpx.post(url, json=10000, timeout=http_timeout(10))
        assert answer.status_code < 300, answer.text
        assert robot.m2.moving_speed == pytest.approx(top)
        refused = httpx.post(
            url,
            content=b"NaN",
            timeout=http_timeout(10),
            headers={"content-type": "application/json"},
        )
        assert refused.status_code == 400 and robot.m2.moving_speed == pytest.approx(top)
        pid = httpx.post(
            f"{robot.http.url}/motor/m3/register/pid/value.json",
            json=[100, 2, 0],
            timeout=http_timeout(10),
        )
        assert pid.status_code < 300, pid.text
        assert robot.m3.pid[0] == pytest.approx(254 / 8)  # the P gain register's top


def test_a_bound_only_server_serves_in_run_until_close() -> None:
    # start_background_services=False: the script serves with run(), which blocks until close.
    robot = PoppyErgoJr(
        simulator="dummy", use_snap=True, snap_port=0, start_background_services=False
    )
    try:
        runner = threading.Thread(target=robot.snap.run, daemon=True)
        runner.start()
        url = f"{robot.snap.url}/motors/motors"
        assert wait_until(lambda: _answers(url), 10.0)
        assert runner.is_alive()  # still serving in run()
    finally:
        robot.close()
    runner.join(10.0)
    assert not runner.is_alive()


def _answers(url: str) -> bool:
    try:
        return "m1" in httpx.get(url, timeout=http_timeout(2)).text
    except httpx.TransportError:
        return False
