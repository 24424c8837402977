"""Poppy Ergo Jr behaviours: a sinusoidal dance, a jump and a gentle power-up."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, ClassVar

from poppy_core import checks
from poppy_core.creatures.postures import ERGO_JR_IDLE, clamp_to_limits
from poppy_core.errors import ArgumentError
from poppy_core.motion import LoopPrimitive, Primitive
from poppy_core.trajectory import control_name

if TYPE_CHECKING:
    from poppy_core.robot import Robot

ERGO_JR_MOTORS: tuple[str, ...] = ("m1", "m2", "m3", "m4", "m5", "m6")

# Poppy documentation (Poppy Ergo Jr specific features): "max_torque set to 0.7, so they can use
# only 70% of their maximal power"; poppy_ergo_jr.py sets torque_limit = 70 on every motor.
ERGO_JR_TORQUE_LIMIT_PCT = 70.0
# poppy_ergo_jr.py setup: m.pid = (4, 2, 0) on every motor (XL-320 P = raw/8, I = raw·1000/2048,
# D = raw·4/1000, the same units as our XL-320 registers).
ERGO_JR_PID: tuple[float, float, float] = (4.0, 2.0, 0.0)


def _control(value: Any, field: str) -> str:
    """A goto control checked by ``control_name`` (``"minijerk"`` is ``"minjerk"``)."""
    del field  # control_name names its own field
    return control_name(value)  # it refuses what is not a control name


@dataclass(frozen=True)
class Wave:
    """One sinusoid of the dance: ``amplitude_deg * sin(2π freq_hz t + phase_deg)``."""

    motors: tuple[str, ...]
    amplitude_deg: float
    freq_hz: float
    phase_deg: float = 0.0


# poppy_ergo_jr/primitives/dance.py: five sinusoids refreshed at 25 Hz, their requests summed by
# the primitive manager (the Ergo Jr's filter is a sum).
DANCE_WAVES: tuple[Wave, ...] = (
    Wave(("m1",), 90.0, 0.25),
    Wave(("m4",), 90.0, 0.25, 180.0),
    Wave(("m5",), 30.0, 0.8),
    Wave(("m6",), 30.0, 0.8, 180.0),
    Wave(ERGO_JR_MOTORS, 10.0, 0.1),
)
DANCE_UPDATE_HZ = 25.0  # dance.py: Sinus(..., 25., ...)
DANCE_INTRO_S = 3.0  # dance.py: goto every motor to 0° in 3 s before dancing
DANCE_SPEED_DPS = 150.0  # dance.py: moving_speed = 150 while dancing

# poppy_ergo_jr/primitives/jump.py: the two postures (degrees) and their pace.
JUMP_UP: dict[str, float] = {"m1": 0, "m2": -10, "m3": -20, "m4": 0, "m5": -35, "m6": -35}
JUMP_DOWN: dict[str, float] = {"m1": 0, "m2": -75, "m3": 55, "m4": 0, "m5": 35, "m6": 35}
JUMP_UP_S = 0.2  # jump.py: up at full speed (moving_speed 0), then sleep 0.2 s
JUMP_DOWN_S = 0.4  # jump.py: down at 250 deg/s, then sleep 0.4 s
JUMP_DOWN_SPEED_DPS = 250.0
JUMP_PID: tuple[float, float, float] = (10.0, 0.0, 0.0)  # jump.py: stiff P gain while jumping

SAFE_POWER_UP_S = 3.0  # postures.py SafePowerUp: IdlePosture(robot, 3.0)


class Dance(LoopPrimitive):
    """Ergo Jr's dance: sums of sinusoids on its joints, after going to 0° (looping).

    Started through a fleet's gate (``shared_start``), the intro ends ``intro_s`` after the
    shared start on every robot and the dance counts from there: the robots dance in phase.

    Args:
        robot: an Ergo Jr.
        amplitude_scale: multiplies every sinusoid's amplitude (1 = pypot's dance).
        tempo_scale: multiplies every sinusoid's frequency (1 = pypot's dance).
        intro_s: seconds to reach 0° on every motor before dancing.
        control: goto control of the intro.
    """

    properties: ClassVar[Sequence[str]] = (
        "amplitude_scale",
        "tempo_scale",
        "intro_s",
        "speed_dps",
        "update_freq",
    )

    def __init__(
        self,
        robot: Robot,
        amplitude_scale: float = 1.0,
        tempo_scale: float = 1.0,
        intro_s: float = DANCE_INTRO_S,
        control: str = "dummy",
    ) -> None:
        super().__init__(robot, DANCE_UPDATE_HZ)
        self.amplitude_scale = amplitude_scale
        self.tempo_scale = tempo_scale
        self.intro_s = intro_s
        self.speed_dps = DANCE_SPEED_DPS
        self.control = control
        self._dance_t0 = 0.0
        self._speeds: dict[str, float] = {}

    control = checks.Checked(_control, "The goto control of the intro: 'minjerk' or 'dummy'.")

    amplitude_scale = checks.Checked(checks.non_negative, "Multiplier of every amplitude (>= 0).")

    tempo_scale = checks.Checked(checks.non_negative, "Multiplier of every frequency (>= 0).")

    intro_s = checks.Checked(
        checks.non_negative, "Seconds to reach the 0° posture before dancing (>= 0)."
    )

    speed_dps = checks.Checked(
        checks.non_negative, "Moving speed while dancing, deg/s (0 = full speed)."
    )

    def _dancers(self) -> list[str]:
        known = {m.name for m in self.real_robot.motors}
        return [name for name in ERGO_JR_MOTORS if name in known]

    def setup(self) -> None:
        """Stiffen, go to 0°, set the dancing speed and light the LEDs green."""
        names = self._dancers()
        self._speeds = {n: self.real_robot.motor(n).moving_speed for n in names}
        for name in names:
            self.robot.motor(name).compliant = False
        # A fleet's shared start: the intro ends at shared_start + intro_s on every robot (a
        # thread that woke late has a shorter one) and the dance counts from there, in phase.
        shared = self.shared_start is not None
        intro_s = max(0.0, self.intro_s - self.elapsed_time) if shared else self.intro_s
        self.robot.goto_position({n: 0.0 for n in names}, intro_s, self.control, wait=True)
        for name in names:
            motor = self.robot.motor(name)
            motor.moving_speed = self.speed_dps
            motor.led = "green"
        self._dance_t0 = self.intro_s if shared else self.elapsed_time

    def positions(self, t_s: float) -> dict[str, float]:
        """Motor name -> the dance's goal (degrees) ``t_s`` seconds into the dance."""
        out = dict.fromkeys(self._dancers(), 0.0)
        for wave in DANCE_WAVES:
            angle = 2 * math.pi * wave.freq_hz * self.tempo_scale * t_s
            value = (
                self.amplitude_scale
                * wave.amplitude_deg
                * math.sin(angle + math.radians(wave.phase_deg))
            )
            for name in wave.motors:
                if name in out:
                    out[name] += value
        return out

    def update(self) -> None:
        """Request the dance's positions at the present time."""
        for name, position in self.positions(self.elapsed_time - self._dance_t0).items():
            self.robot.motor(name).goal_position = position

    def teardown(self) -> None:
        """Hold the last goals, give back the moving speeds and turn the LEDs off."""
        for name, speed in self._speeds.items():
            motor = self.robot.motor(name)
            motor.moving_speed = speed
            motor.led = "off"


class Jump(Primitive):
    """Ergo Jr folds, then unfolds at full speed: with a light base, it jumps.

    Args:
        robot: an Ergo Jr.
        jumps: how many jumps (0: until stopped).
    """

    properties: ClassVar[Sequence[str]] = ("jumps",)

    def __init__(self, robot: Robot, jumps: int = 1) -> None:
        super().__init__(robot)
        self.jumps = jumps
        self._pids: dict[str, tuple[float, float, float]] = {}

    @property
    def jumps(self) -> int:
        """Number of jumps; 0 jumps until stopped."""
        return self._jumps

    @jumps.setter
    def jumps(self, value: int) -> None:
        if isinstance(value, bool) or not isinstance(value, int) or value < 0:
            raise ArgumentError(
                f"jumps must be a whole number >= 0, got {value!r}", field="jumps", value=value
            )
        self._jumps = value

    def setup(self) -> None:
        """Stiffen with a high P gain (the gains are put back at the end)."""
        names = [n for n in JUMP_UP if n in {m.name for m in self.real_robot.motors}]
        self._pids = {}
        for name in names:
            self.robot.motor(name).compliant = False
            real = self.real_robot.motor(name)
            if real.model.has_register("p_gain"):
                self._pids[name] = real.pid
                real.pid = JUMP_PID

    def _pose(self, posture: dict[str, float], speed_dps: float) -> None:
        for name, position in clamp_to_limits(self.real_robot, posture).items():
            motor = self.robot.motor(name)
            motor.moving_speed = speed_dps
            motor.goal_position = position

    def run(self) -> None:
        """Fold, then (up fast, fold) once per jump."""
        self._pose(JUMP_DOWN, JUMP_DOWN_SPEED_DPS)
        if self.sleep(JUMP_DOWN_S):
            return
        done = 0
        while not self.should_stop() and (self.jumps == 0 or done < self.jumps):
            if self.should_pause():
                self.wait_to_resume()
                continue
            self._pose(JUMP_UP, 0.0)
            if self.sleep(JUMP_UP_S):
                return
            self._pose(JUMP_DOWN, JUMP_DOWN_SPEED_DPS)
            if self.sleep(JUMP_DOWN_S):
                return
            done += 1

    def teardown(self) -> None:
        """Put the gains back."""
        for name, pid in self._pids.items():
            self.real_robot.motor(name).pid = pid


class SafePowerUp(Primitive):
    """Power up gently: limited torque, then a slow move to the idle posture.

    Args:
        robot: an Ergo Jr.
        duration: seconds to reach the idle posture.
        torque_limit: torque limit (%) set on every motor before stiffening.
        control: goto control.
    """

    properties: ClassVar[Sequence[str]] = ("duration", "torque_limit", "control")

    def __init__(
        self,
        robot: Robot,
        duration: float = SAFE_POWER_UP_S,
        torque_limit: float = ERGO_JR_TORQUE_LIMIT_PCT,
        control: str = "dummy",
    ) -> None:
        super().__init__(robot)
        self.duration = duration
        self.torque_limit = torque_limit
        self.control = control

    duration = checks.Checked(checks.non_negative, "Seconds to reach the idle posture (>= 0).")

    control = checks.Checked(_control, "The goto control: 'minjerk' or 'dummy'.")

    @property
    def torque_limit(self) -> float:
        """Torque limit in % (0..100) given to every motor."""
        return self._torque_limit

    @torque_limit.setter
    def torque_limit(self, value: float) -> None:
        self._torque_limit = checks.in_range(value, 0.0, 100.0, "torque_limit", "%")

    def run(self) -> None:
        """Limit the torque, stiffen, go to the idle posture and wait until it is reached."""
        posture = clamp_to_limits(self.real_robot, ERGO_JR_IDLE)
        for name in posture:
            motor = self.robot.motor(name)
            if motor.real_motor.model.has_torque_limit:
                motor.torque_limit = self.torque_limit
            motor.compliant = False
        self.robot.goto_position(posture, self.duration, self.control, wait=True)

    def teardown(self) -> None:
        """Full speed again (pypot's SafePowerUp ends with moving_speed = 0)."""
        for name in clamp_to_limits(self.real_robot, ERGO_JR_IDLE):
            self.robot.motor(name).moving_speed = 0.0
