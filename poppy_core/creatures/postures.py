"""Posture primitives of the creatures: Ergo Jr base/rest/curious/tetris, Torso's init position,
Humanoid stand/sit.

Each one is a ``SimplePosture`` that moves with its creature's default goto control, keeps the
targets inside the motors' angle limits and, on Ergo Jr, colours the LEDs as pypot's postures do.
"""

from __future__ import annotations

import time
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, ClassVar

from poppy_core.errors import ArgumentError
from poppy_core.motion import SimplePosture
from poppy_core.trajectory import CONTROLS, clamp_goal

if TYPE_CHECKING:
    from poppy_core.robot import Robot

# Durations: poppy_ergo_jr attaches its postures with a 2 s duration (poppy_ergo_jr.py setup).
ERGO_JR_POSTURE_S = 2.0
# Humanoid stand/sit: 2 s, the same pace as the Ergo Jr postures (poppy-humanoid is not
# installed here to read its own value).
HUMANOID_POSTURE_S = 2.0

# poppy_ergo_jr/primitives/postures.py (BasePosture): every motor at 0°.
ERGO_JR_BASE: dict[str, float] = {f"m{i}": 0.0 for i in range(1, 7)}
# poppy_ergo_jr/primitives/postures.py (RestPosture), degrees.
ERGO_JR_REST: dict[str, float] = {
    "m1": 0.0,
    "m2": -90.0,
    "m3": 35.0,
    "m4": 0.0,
    "m5": 55.0,
    "m6": -5.0,
}
# poppy_ergo_jr/primitives/postures.py (CuriousPosture), degrees.
ERGO_JR_CURIOUS: dict[str, float] = {
    "m1": 0.0,
    "m2": -15.0,
    "m3": 40.0,
    "m4": 0.0,
    "m5": -35.0,
    "m6": -60.0,
}
# poppy_ergo_jr/primitives/postures.py (TetrisPosture, yellow LEDs), degrees.
ERGO_JR_TETRIS: dict[str, float] = {
    "m1": 0.0,
    "m2": -90.0,
    "m3": 90.0,
    "m4": 0.0,
    "m5": -90.0,
    "m6": -90.0,
}
# poppy_torso/primitives/posture.py (InitPosition): every motor to 0° in 3 s, then the bust
# leans 4° (bust_y) in 1 s.
TORSO_INIT_S = 3.0
TORSO_INIT_LEAN: tuple[str, float, float] = ("bust_y", 4.0, 1.0)
# poppy_ergo_jr/primitives/postures.py (IdlePosture), degrees; SafePowerUp goes there (m2's
# user range is [-125, 90]: the profile's [-90, 125] is in the motor frame and m2 is indirect).
ERGO_JR_IDLE: dict[str, float] = {
    "m1": 0.0,
    "m2": -110.0,
    "m3": 65.0,
    "m4": 0.0,
    "m5": 34.0,
    "m6": 20.0,
}

# Poppy documentation (poppy_humanoid library): "stand_position: the robot moves to standing
# position (0 to all motors)".
# Sit, "legs bent with heels under the buttock" (same documentation): pypot's numbers
# (poppy-humanoid, primitives/posture.py, SitPosition): thighs raised 39°, knees bent 134°, the
# same angles on both legs (the legs' user frames are mirror images: the profiles' limits,
# motor frame, give l_knee_y and r_knee_y both [-3.5, 134] in the user frame). pypot then frees
# the knees and ankles; poppy's posture holds them.
HUMANOID_SIT: dict[str, float] = {
    "l_hip_y": -39.0,
    "r_hip_y": -39.0,
    "l_knee_y": 134.0,
    "r_knee_y": 134.0,
    "abs_x": 0.0,
    "abs_y": 3.0,
    "abs_z": 0.0,
    "bust_x": 0.0,
    "bust_y": 0.0,
}


def humanoid_sit() -> dict[str, float]:
    """The sit posture (pypot's SitPosition targets)."""
    return dict(HUMANOID_SIT)


def clamp_to_limits(robot: Robot, posture: Mapping[str, float]) -> dict[str, float]:
    """The posture restricted to the robot's motors, each target inside its angle limits."""
    names = {m.name for m in robot.motors}
    out: dict[str, float] = {}
    for name, value in posture.items():
        if name in names:
            motor = robot.motor(name)
            out[name] = clamp_goal(float(value), None if motor.wheel_mode else motor.angle_limit)
    return out


class CreaturePosture(SimplePosture):
    """A posture reached with a chosen goto control, optionally lighting the LEDs.

    Args:
        robot: the robot.
        target_position: motor name -> degrees (motors the robot lacks are left out, targets
            are clamped to the angle limits).
        duration: seconds to reach it.
        control: ``"minjerk"`` or ``"dummy"`` (the creature's default goto behaviour).
        led: an LED colour to show while moving (``"blue"``...), None to leave the LEDs alone.
    """

    properties: ClassVar[Sequence[str]] = ("duration", "target_position", "control")

    def __init__(
        self,
        robot: Robot,
        target_position: Mapping[str, float],
        duration: float,
        control: str = "minjerk",
        led: str | None = None,
    ) -> None:
        super().__init__(robot, duration, clamp_to_limits(robot, target_position))
        self.control = control
        self.led = led

    @property
    def control(self) -> str:
        """The goto control: ``"minjerk"`` or ``"dummy"``."""
        return self._control

    @control.setter
    def control(self, value: str) -> None:
        if value not in CONTROLS:
            raise ArgumentError(
                f"control must be one of {', '.join(CONTROLS)}, not {value!r}",
                field="control",
                value=value,
            )
        self._control = value

    def setup(self) -> None:
        """Note the moving speeds, stiffen the posture's motors and light their LEDs."""
        super().setup()
        if self.led is not None:
            for name in self.target_position:
                self.robot.motor(name).led = self.led

    def run(self) -> None:
        """Move with the chosen control; return once the posture is reached (or when stopped)."""
        start = time.monotonic()
        self.robot.goto_position(self.target_position, self.duration, self.control)
        self.sleep(self.duration - (time.monotonic() - start))

    def teardown(self) -> None:
        """Give the motors back their moving speeds and turn the LEDs off (as pypot does)."""
        super().teardown()
        if self.led is not None:
            for name in self.target_position:
                self.robot.motor(name).led = "off"


class InitPosition(CreaturePosture):
    """The Torso's ``init_position``: stiff, every motor to 0°, then the bust leans forward."""

    def __init__(self, robot: Robot, control: str = "minjerk") -> None:
        zeros = {m.name: 0.0 for m in robot.motors}
        super().__init__(robot, zeros, TORSO_INIT_S, control)

    def run(self) -> None:
        """Reach 0° everywhere, then lean ``bust_y`` (when the robot has it)."""
        super().run()
        name, angle, duration = TORSO_INIT_LEAN
        if self.should_stop() or name not in self.target_position:
            return
        lean = clamp_to_limits(self.real_robot, {name: angle})
        start = time.monotonic()
        self.robot.goto_position(lean, duration, self.control)
        self.sleep(duration - (time.monotonic() - start))
