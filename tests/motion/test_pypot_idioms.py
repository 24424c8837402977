"""The idioms of the Poppy creature packages' primitives, on poppy (no download needed).

The packages themselves replay in tests/creatures/test_creature_packages.py; these are the
pypot habits they use, written the way they write them.
"""

from __future__ import annotations

import pytest

from poppy_core import from_profile
from poppy_core.errors import ArgumentError, RegisterError
from poppy_core.motion import LoopPrimitive, Primitive, SimplePosture
from poppy_core.robot import Robot
from tests.helpers.fixtures import ergo_fixture
from tests.helpers.waiting import eventually

ergo = ergo_fixture(scope="module", stiff=True)


class LeaningPosture(SimplePosture):
    """poppy-ergo-jr's way: the posture and the LEDs as read-only properties."""

    @property
    def target_position(self) -> dict[str, float]:  # type: ignore[override]
        return {m.name: -10.0 if m.name == "m3" else 0.0 for m in self.robot.motors}

    @property
    def leds(self) -> dict[object, str]:
        return {m: "pink" for m in self.robot.motors}


def test_a_posture_with_its_own_read_only_target_position(ergo: Robot) -> None:
    posture = LeaningPosture(ergo, 0.5)
    speeds = {m.name: m.moving_speed for m in ergo.motors}
    posture.start()
    assert eventually(lambda: ergo.m1.led == "pink", 15.0)  # lit while it moves
    assert posture.wait_to_stop(15.0)
    assert ergo.m3.goal_position == pytest.approx(-10.0)
    assert eventually(lambda: all(m.led == "off" for m in ergo.motors), 15.0)
    assert {m.name: m.moving_speed for m in ergo.motors} == pytest.approx(speeds, abs=1.0)
    with pytest.raises(ArgumentError, match="defines its target_position itself"):
        LeaningPosture(ergo, 0.5, {"m1": 0.0})


def test_a_posture_given_its_target_still_takes_it(ergo: Robot) -> None:
    posture = SimplePosture(ergo, 0.3, {"m2": 5.0})
    posture.target_position = {"m2": 7.0}
    posture.start()
    assert posture.wait_to_stop(15.0)
    assert ergo.m2.goal_position == pytest.approx(7.0)


def test_a_loop_primitive_has_pypots_period(ergo: Robot) -> None:
    class Ticking(LoopPrimitive):
        def setup(self) -> None:  # poppy-torso's ArmsTurnCompliant.setup
            self.window = int(0.2 * (1.0 / self.period))

    loop = Ticking(ergo, 50)
    assert loop.period == pytest.approx(0.02)
    loop.start()
    loop.stop()
    assert loop.window == 10
    loop.period = 0.1
    assert loop.update_freq == pytest.approx(10.0)
    with pytest.raises(ArgumentError, match="period"):
        loop.period = 0.0


def test_hasattr_pid_picks_the_motors_with_gains() -> None:
    # poppy-humanoid's StandPosition: `[m for m in self.robot.motors if hasattr(m, 'pid')]`
    with from_profile("humanoid", sim=True, sensors=False) as humanoid:
        with_gains = {m.name for m in humanoid.motors if hasattr(m, "pid")}
        assert "head_z" not in with_gains and "abs_y" in with_gains  # AX-12A / MX-64
        assert with_gains == {m.name for m in humanoid.motors if m.model.name.startswith("MX")}
        with pytest.raises(RegisterError, match="has no PID gains"):
            humanoid.head_z.pid = (1.0, 0.0, 0.0)

        class Gains(Primitive):
            def setup(self) -> None:  # a primitive sets the gains of its motors (pypot's)
                for m in self.robot.motors:
                    if hasattr(m, "pid"):
                        m.pid = (6.0, 2.0, 0.0)

        gains = Gains(humanoid)
        gains.start()
        gains.stop()
        assert humanoid.abs_y.pid == (6.0, 2.0, 0.0)
