"""The Ergo Jr's demo primitives of poppy-ergo-jr: a tinsel of LEDs, a stubborn arm, a chicken
head that stays level, and a posture puzzle.

The behaviours (what each one does, its postures, colours and timings) are those of
poppy-ergo-jr's ``How_to_add_primitive_FR.py`` (Tinsel, Tetu, Poule, Puzzel), attached there as
``tinsel_demo``, ``stubborn_demo``, ``chicken_demo`` and ``puzzel_demo``; the code is poppy's.
Every demo but the tinsel starts and ends in the demo posture, reached at 100 °/s.
"""

from __future__ import annotations

import random
import time
from collections.abc import Sequence
from typing import TYPE_CHECKING, ClassVar

from poppy_core import checks
from poppy_core.creatures.postures import clamp_to_limits
from poppy_core.motion import Primitive

if TYPE_CHECKING:
    from poppy_core.robot import Robot

MOTORS = ("m1", "m2", "m3", "m4", "m5", "m6")
# BaseDemo's start and end posture (degrees, m1..m6) and the pace it is reached at.
DEMO_POSTURE = (0.0, -45.0, 25.0, 0.0, 45.0, -25.0)
DEMO_SPEED_DPS = 100.0
TINSEL_COLORS = ("green", "red", "yellow", "blue", "pink", "cyan", "white", "off")
POLL_S = 0.01  # the demos look at the arm every 10 ms
MIN_MOVE_S = 0.05  # pypot moved at once when the arm was already there (a 0 s goto)


class DemoPrimitive(Primitive):
    """What the demos share: the demo posture, pause-aware waits, LEDs and a blinking countdown."""

    properties: ClassVar[Sequence[str]] = ("countdown_s",)
    countdown_s = 5.0

    def positions(self) -> list[float]:
        """The present positions of m1..m6."""
        return [self.real_robot.motor(name).present_position for name in MOTORS]

    def distances(self, posture: Sequence[float]) -> list[float]:
        """|present - posture| per motor, degrees."""
        return [abs(p - q) for p, q in zip(self.positions(), posture, strict=True)]

    def posture_is(self, posture: Sequence[float], tolerance_deg: float = 2.0) -> bool:
        """True when every motor is within ``tolerance_deg`` of ``posture``."""
        return max(self.distances(posture)) <= tolerance_deg

    def wait(self, seconds: float) -> bool:
        """Wait ``seconds`` (paused time left out); True when the demo should stop."""
        end = time.monotonic() + max(0.0, seconds)
        while not self.should_stop():
            if self.should_pause():
                paused_at = time.monotonic()
                self.wait_to_resume()
                end += time.monotonic() - paused_at
            left = end - time.monotonic()
            if left <= 0:
                return False
            self.sleep(min(left, 0.05))
        return True

    def leds(self, color: str, motors: Sequence[str] = MOTORS) -> None:
        """Request ``color`` on the LEDs of ``motors``."""
        for name in motors:
            self.robot.motor(name).led = color

    def stiff(self, on: bool, motors: Sequence[str] = MOTORS) -> None:
        """Request the motors stiff, or free (a free motor keeps no goal request: a hand moves
        it, and a goal left over would pull it back once something stiffens it)."""
        for name in motors:
            if not on:
                self._forget_goal(name)
            self.robot.motor(name).compliant = not on

    def _forget_goal(self, name: str) -> None:
        """Drop the motor's requests but its LED colour."""
        motor = self.robot.motor(name)
        led = motor.requests().get("led")
        motor.clear()
        if led is not None:
            motor.led = led

    def move_to(self, posture: Sequence[float], duration_s: float | None = None) -> float:
        """Stiffen and request ``posture``, by default at the demos' pace; returns the duration.

        The move starts from where the arm is (a hand may have moved it since the last request):
        the old goal requests are dropped, the LED requests kept.
        """
        if duration_s is None:
            duration_s = int(max(self.distances(posture))) / DEMO_SPEED_DPS
        duration_s = max(duration_s, MIN_MOVE_S)
        targets = clamp_to_limits(self.real_robot, dict(zip(MOTORS, posture, strict=True)))
        for name in targets:
            self._forget_goal(name)
        self.stiff(True)
        self.robot.goto_position(targets, duration_s, "minjerk")
        return duration_s

    def countdown(self) -> bool:
        """Blink the LEDs green, faster and faster, for about ``countdown_s``; True to stop."""
        steps = max(1, int(self.countdown_s * 1.2))
        for i in range(steps):
            self.leds("off")
            if self.wait(max(0.05, 0.5 - 0.5 * i / steps) * self.countdown_s / 5.0):
                return True
            self.leds("green")
            if self.wait(0.5 * self.countdown_s / 5.0):
                return True
        return False

    def rest(self) -> None:
        """Back to the demo posture, then compliant with the LEDs off (blocking, as pypot's)."""
        time.sleep(self.move_to(DEMO_POSTURE) + 0.2)
        self.stiff(False)
        self.leds("off")
        time.sleep(0.1)

    def setup(self) -> None:
        """Start from the demo posture, compliant, LEDs off."""
        self.rest()

    def teardown(self) -> None:
        """End in the demo posture, compliant, LEDs off."""
        self.rest()


class TinselDemo(Primitive):
    """``tinsel_demo``: every LED takes each of ``colors`` in turn, ``freq`` colours a second."""

    properties: ClassVar[Sequence[str]] = ("colors", "freq")

    def __init__(
        self, robot: Robot, colors: Sequence[str] = TINSEL_COLORS, freq: float = 2.0
    ) -> None:
        super().__init__(robot)
        self.colors = list(colors)
        self.freq = checks.rate(freq, "freq")

    def run(self) -> None:
        """Cycle the colours until stopped (pauses hold the present colour)."""
        while not self.should_stop():
            for color in list(self.colors):
                if self.should_pause():
                    self.wait_to_resume()
                if self.should_stop():
                    return
                for motor in self.robot.motors:
                    motor.led = color
                if self.sleep(1.0 / self.freq):
                    return


class StubbornDemo(DemoPrimitive):
    """``stubborn_demo``: after a countdown the arm keeps the posture it was left in; moved away
    it turns yellow, and if it is not put back within 2 s it turns red and goes back itself."""

    properties: ClassVar[Sequence[str]] = ("countdown_s", "tolerance_deg")
    tolerance_deg = 6.0  # how far from its posture the arm may be moved unnoticed
    give_up_deg = 45.0  # moved further than this, it does not wait the 2 s
    notice_s, allow_s, back_s, hold_s = 1.0, 2.0, 0.5, 1.5

    def setup(self) -> None:
        """Demo posture, countdown, then the present posture is the one to keep."""
        super().setup()
        self.countdown()
        self.kept = [float(round(p)) for p in self.positions()]

    def run(self) -> None:
        """Watch the posture every 10 ms; take it back when it was changed for good."""
        while not self.should_stop():
            if self.should_pause():
                self.wait_to_resume()
            if not self.posture_is(self.kept, self.tolerance_deg):
                self.leds("yellow")
                if self.wait(self.notice_s):
                    return
                waited = 0.0
                while self.posture_is(self.kept, self.give_up_deg) and waited < self.allow_s:
                    if self.wait(POLL_S):
                        return
                    waited += POLL_S
                if not self.posture_is(self.kept, self.tolerance_deg):
                    self.leds("red")
                    self.move_to(self.kept, self.back_s)
                    if self.wait(self.hold_s):
                        return
                self.leds("green")
                self.stiff(False)
            if self.wait(POLL_S):
                return


class ChickenDemo(DemoPrimitive):
    """``chicken_demo``: the head (m4-m6, red, stiff) mirrors the base (m1-m3, green, free), so
    that moving the base by hand keeps the head level, as a chicken's."""

    def setup(self) -> None:
        """Demo posture, then the head stiff and red, the base free and green."""
        super().setup()
        self.leds("red", MOTORS[3:])
        self.stiff(True, MOTORS[3:])
        self.leds("green", MOTORS[:3])
        self.stiff(False, MOTORS[:3])

    def run(self) -> None:
        """Every 10 ms: m4, m5, m6 go to minus m1, m2, m3."""
        while not self.should_stop():
            if self.should_pause():
                self.wait_to_resume()
            for base, head in zip(MOTORS[:3], MOTORS[3:], strict=True):
                goal = -self.real_robot.motor(base).present_position
                low, high = self.real_robot.motor(head).angle_limit
                self.robot.motor(head).goal_position = min(max(goal, low), high)
            if self.wait(POLL_S):
                return


# Puzzel's figures (m1..m6, degrees); m1, m4 and m6 are then set from LEVEL_ANGLES by level.
FIGURES = (
    (0, 0, -90, 0, 45, 0),
    (0, 0, 90, 0, -45, 0),
    (0, 0, 0, 0, -90, 0),
    (0, 0, 0, 0, 90, 0),
    (0, 45, -90, 0, 0, 0),
    (0, 45, -90, 0, 90, 0),
    (0, -45, 90, 0, 0, 0),
    (0, -45, 90, 0, -90, 0),
)
LEVEL_ANGLES = (-75, -45, 0, 0, 45, 75)
PRECISIONS = {"easy": 20.0, "normal": 10.0, "hard": 5.0}
LEVELS = {"veryeasy": 1, "easy": 2, "normal": 3, "hard": 4, "veryhard": 5}
FIGURES_TO_WIN = 6


def puzzle_figure(level: int, rng: random.Random) -> list[float]:
    """A figure to reproduce: level 0 the first one, 1-5 more and more of it chosen at random."""
    figure = list(FIGURES[0] if level <= 1 else rng.choice(FIGURES))
    if level == 0:
        return [float(v) for v in figure]
    if level <= 2:
        a = rng.choice(LEVEL_ANGLES)
        turns = (a, a, a)
    elif level == 3:
        a, b = rng.sample(LEVEL_ANGLES, 2)
        turns = (a, b, a)
    elif level == 4:
        a, b, c = rng.sample(LEVEL_ANGLES, 3)
        turns = (a, b, c)
    else:
        turns = (rng.randrange(-75, 75), rng.randrange(-75, 75), rng.randrange(-75, 75))
    figure[0], figure[3], figure[5] = turns
    return [float(v) for v in figure]


class PuzzleDemo(DemoPrimitive):
    """``puzzel_demo``: the arm shows a figure (red), goes back, and the player has
    ``search_s`` to put it in that figure by hand (green, free). Found within ``precision``
    degrees, one more LED lights and a harder figure comes; missed, the arm shows it again and
    the game starts over. Six found: the arm plays them back and dances.

    ``level_growing()`` (the default) makes each figure harder than the last; ``level_veryeasy``
    .. ``level_veryhard`` keep one level; ``precision_easy/normal/hard``: 20, 10, 5 degrees.
    """

    properties: ClassVar[Sequence[str]] = ("countdown_s", "level", "precision", "search_s")
    methods: ClassVar[Sequence[str]] = (
        *Primitive.methods,
        "level_growing",
        "level_veryeasy",
        "level_easy",
        "level_normal",
        "level_hard",
        "level_veryhard",
        "precision_easy",
        "precision_normal",
        "precision_hard",
    )
    show_s, search_s, replay_hold_s, dance_s = 5.0, 10.0, 2.0, 5.0

    def __init__(self, robot: Robot, level: int = 0, precision: float = 20.0) -> None:
        super().__init__(robot)
        self.level = level
        self.precision = checks.positive(precision, "precision")
        self.manual = False
        self.found: list[list[float]] = []
        self.rng = random.Random()
        self.phase = "idle"  # show, search, judge, replay, dance: where the round is

    @property
    def score(self) -> int:
        """Figures found in a row."""
        return len(self.found)

    def level_growing(self) -> None:
        """Each figure one level harder than the last."""
        self.manual, self.level = False, 0

    def _level(self, name: str) -> None:
        self.manual, self.level = True, LEVELS[name]

    def level_veryeasy(self) -> None:
        """Level 1 for every figure."""
        self._level("veryeasy")

    def level_easy(self) -> None:
        """Level 2 for every figure."""
        self._level("easy")

    def level_normal(self) -> None:
        """Level 3 for every figure."""
        self._level("normal")

    def level_hard(self) -> None:
        """Level 4 for every figure."""
        self._level("hard")

    def level_veryhard(self) -> None:
        """Level 5 for every figure."""
        self._level("veryhard")

    def precision_easy(self) -> None:
        """Found within 20°."""
        self.precision = PRECISIONS["easy"]

    def precision_normal(self) -> None:
        """Found within 10°."""
        self.precision = PRECISIONS["normal"]

    def precision_hard(self) -> None:
        """Found within 5°."""
        self.precision = PRECISIONS["hard"]

    def run(self) -> None:
        """Rounds until stopped: show, hide, let the player search, judge."""
        while not self.should_stop():
            figure = puzzle_figure(self.level if self.manual else len(self.found), self.rng)
            if self.play_round(figure):
                return

    def play_round(self, figure: list[float]) -> bool:
        """One figure; True when the demo should stop."""
        self.phase = "show"
        self.leds("red")
        if self.wait(self.move_to(figure)) or self.wait(self.show_s):
            return True
        if self.wait(self.move_to(DEMO_POSTURE, 1.0)):
            return True
        self.stiff(False)
        self.leds("green")
        self.phase = "search"
        if self.countdown_search():
            return True
        self.phase = "judge"
        if self.posture_is(figure, self.precision):
            self.found.append(figure)
            for name in MOTORS[: len(self.found)]:
                self.leds("green", [name])
        else:
            self.leds("red")
            if self.wait(self.move_to(figure, 1.0)) or self.wait(self.replay_hold_s):
                return True
            self.found = []
        if len(self.found) >= FIGURES_TO_WIN and self.celebrate():
            return True
        return self.wait(self.move_to(DEMO_POSTURE, 1.0))

    def countdown_search(self) -> bool:
        """The player's time, shown by the LEDs blinking green faster and faster."""
        saved, self.countdown_s = self.countdown_s, self.search_s
        try:
            return self.countdown()
        finally:
            self.countdown_s = saved

    def celebrate(self) -> bool:
        """Play the found figures back, dance, and start again from zero."""
        self.phase = "replay"
        for figure in self.found:
            if self.wait(self.move_to(figure)):
                return True
        self.found = []
        dance = getattr(self.real_robot, "dance", None)
        if not isinstance(dance, Primitive):
            return False
        self.robot.clear()  # the dance moves alone
        self.phase = "dance"
        dance.start()
        stop = self.wait(self.dance_s)
        dance.halt()
        return stop
