"""The Ergo Jr's demos of poppy-ergo-jr (tinsel, stubborn, chicken, puzzle), as notebooks start
them: ``poppy.<name>_demo.start()`` ... ``stop()``. Timings are shortened on the instances."""

from __future__ import annotations

import random
from collections.abc import Iterator

import pytest

from poppy_core.creatures.ergo_demos import DEMO_POSTURE, FIGURES, LEVEL_ANGLES, puzzle_figure
from poppy_core.pypot import PoppyErgoJr
from poppy_core.robot import Robot
from tests.creatures.helpers import wait_until

WAIT_S = 20.0


@pytest.fixture
def poppy() -> Iterator[Robot]:
    with PoppyErgoJr(simulator="dummy") as robot:
        yield robot


def _at(robot: Robot, posture: tuple[float, ...] | list[float], tolerance: float = 3.0) -> bool:
    return all(
        abs(m.present_position - v) <= tolerance for m, v in zip(robot.motors, posture, strict=True)
    )


def _push(robot: Robot, name: str, position: float) -> None:
    """A hand moving one motor (at full speed): stiff where the hand holds it."""
    motor = robot.motor(name)
    motor.compliant = False
    motor.moving_speed = 0
    motor.goal_position = position


def test_tinsel_cycles_the_colours_until_stopped(poppy: Robot) -> None:
    tinsel = poppy.tinsel_demo
    tinsel.freq = 20.0
    tinsel.colors = ["red", "green", "blue"]
    seen: set[str] = set()
    tinsel.start()
    assert wait_until(
        lambda: seen.update({m.led for m in poppy.motors}) or {"red", "green", "blue"} <= seen,
        WAIT_S,
    )
    tinsel.stop()
    assert not tinsel.is_alive() and len({m.led for m in poppy.motors}) == 1


def test_chicken_keeps_the_head_level(poppy: Robot) -> None:
    chicken = poppy.chicken_demo
    chicken.start()
    assert wait_until(
        lambda: (
            [m.led for m in poppy.motors] == ["green"] * 3 + ["red"] * 3
            and [m.compliant for m in poppy.motors] == [True] * 3 + [False] * 3
        ),
        WAIT_S,
    )
    assert _at(poppy, DEMO_POSTURE)
    _push(poppy, "m1", 30.0)
    _push(poppy, "m3", 40.0)
    assert wait_until(
        lambda: abs(poppy.m4.present_position + 30) < 2 and abs(poppy.m6.present_position + 40) < 2,
        WAIT_S,
    )
    chicken.stop()
    assert {m.led for m in poppy.motors} == {"off"} and poppy.compliant


def test_stubborn_takes_its_posture_back(poppy: Robot) -> None:
    stubborn = poppy.stubborn_demo
    stubborn.countdown_s = 0.5
    stubborn.notice_s, stubborn.allow_s, stubborn.hold_s = 0.2, 0.3, 0.3
    stubborn.start()
    assert wait_until(lambda: hasattr(stubborn, "kept"), WAIT_S)  # set after the countdown
    kept = list(stubborn.kept)
    assert _at(poppy, kept)
    colours: set[str] = set()
    _push(poppy, "m2", kept[1] + 30.0)
    assert wait_until(
        lambda: colours.update({m.led for m in poppy.motors}) or {"yellow", "red"} <= colours,
        WAIT_S,
    )
    assert wait_until(
        lambda: _at(poppy, kept, 6.0) and {m.led for m in poppy.motors} == {"green"}, WAIT_S
    )
    stubborn.stop()
    assert _at(poppy, DEMO_POSTURE) and {m.led for m in poppy.motors} == {"off"}


def test_puzzle_figures_by_level() -> None:
    rng = random.Random(4)
    assert puzzle_figure(0, rng) == list(FIGURES[0])
    for level in (1, 2, 3, 4, 5):
        figure = puzzle_figure(level, rng)
        turns = (figure[0], figure[3], figure[5])
        assert tuple(0.0 if i in (0, 3, 5) else v for i, v in enumerate(figure)) in FIGURES
        if level <= 2:
            assert len(set(turns)) == 1 and turns[0] in LEVEL_ANGLES
        elif level == 3:
            assert turns[0] == turns[2] and turns[0] != turns[1]
        elif level == 4:
            assert len(set(turns)) == 3 and set(turns) <= set(LEVEL_ANGLES)
        else:
            assert all(-75 <= t < 75 for t in turns)


def test_puzzle_round_found_then_missed(poppy: Robot) -> None:
    puzzle = poppy.puzzel_demo
    puzzle.show_s, puzzle.search_s, puzzle.replay_hold_s = 0.3, 4.0, 0.3
    puzzle.countdown_s = 0.3
    puzzle.precision_easy()
    puzzle.start()
    # Round 1 (level 0: the first figure): the arm shows it in red...
    assert wait_until(lambda: puzzle.phase == "show", WAIT_S)
    figure = list(FIGURES[0])
    assert wait_until(lambda: _at(poppy, figure), WAIT_S)
    # ... goes back, and the player puts it in the figure during the search.
    assert wait_until(lambda: puzzle.phase == "search" and poppy.compliant, WAIT_S)  # free
    for motor, value in zip(poppy.motors, figure, strict=True):
        _push(poppy, motor.name, value)
    assert wait_until(lambda: puzzle.score == 1, WAIT_S), (
        puzzle.phase,
        [round(m.present_position) for m in poppy.motors],
    )
    # Round 2: the player does nothing; the figure is shown again and the score is lost.
    assert wait_until(lambda: puzzle.phase == "search", WAIT_S)
    assert wait_until(lambda: puzzle.phase != "search", WAIT_S)
    assert wait_until(lambda: puzzle.score == 0, WAIT_S)
    puzzle.stop()
    assert not puzzle.is_alive()
    assert _at(poppy, DEMO_POSTURE)
