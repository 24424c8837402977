"""`poppy emulate --control`'s hand commands: move motors as a hand would (``move 3 30 --over 2``).

Commands (a motor is its ID, the servo's own angle, or with a profile its NAME, the robot's
angle as the profile mounts it):

=================================  ==========================================================
``move ID|NAME DEG [--over S]``    the hand moves the horn to DEG over S seconds (minimum
                                   jerk; ``--linear`` for a constant speed), then holds it
``play FILE [--speed X]``          the hand plays a move file (.move or pypot .json; needs a
                                   profile: its motors are named), then holds the last frame
``release ID|NAME|all``            the hand lets go
``where``                          every motor's present position (and what the hand holds)
=================================  ==========================================================
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

from poppy_core.emulator.control import ControlError
from poppy_core.emulator.hand import Hand
from poppy_core.errors import PoppyError
from poppy_core.robot.frames import Orientation, to_motor, to_user

WORDS: tuple[str, ...] = ("move", "play", "release", "where")
HELP = (
    "hand: move ID|NAME DEG [--over S] [--linear] | play FILE [--speed X] | "
    "release ID|NAME|all | where"
)
MOVE_USAGE = "move ID|NAME DEGREES [--over SECONDS] [--linear]"


@dataclass(frozen=True)
class HandJoint:
    """A named motor of the profile: its id and how it is mounted."""

    id: int
    orientation: Orientation = "direct"
    offset: float = 0.0


class HandCommands:
    """Runs hand command lines on ``hand``.

    Args:
        hand: the hand on the emulated buses.
        joints: the profile's motors by name (empty without a profile).
    """

    def __init__(self, hand: Hand, joints: Mapping[str, HandJoint] | None = None) -> None:
        self.hand = hand
        self.joints = dict(joints or {})

    def execute(self, name: str, args: list[str]) -> str:
        """Run ``name`` (one of ``WORDS``) with ``args``; says what was done in one line.

        Raises:
            ControlError: a bad command line, an unknown motor, an unreadable move file.
        """
        try:
            if name == "move":
                return self._move(args)
            if name == "play":
                return self._play(args)
            if name == "release":
                return self._release(args)
            if args:
                raise ControlError("usage: where")
            return self._where()
        except KeyError as exc:
            raise ControlError(str(exc.args[0])) from None
        except PoppyError as exc:
            raise ControlError(str(exc).splitlines()[0]) from None

    def _joint(self, text: str) -> tuple[int, HandJoint | None]:
        """(motor id, its joint when named) of ``text``."""
        if text.isdigit():
            return int(text), None
        joint = self.joints.get(text)
        if joint is None:
            known = ", ".join(self.joints) or "none without --profile: give an ID"
            raise ControlError(f"no motor {text!r} (names: {known})")
        return joint.id, joint

    def _move(self, args: list[str]) -> str:
        words = [a for a in args if a != "--linear"]
        over = _take_option(words, "--over", 0.0, MOVE_USAGE, "--over takes seconds")
        if len(words) != 2:
            raise ControlError(f"usage: {MOVE_USAGE}")
        motor_id, joint = self._joint(words[0])
        degrees = _number(words[1], "move takes degrees")
        motor_deg = degrees if joint is None else to_motor(degrees, joint.orientation, joint.offset)
        profile = "linear" if "--linear" in args else "minjerk"
        self.hand.move(motor_id, motor_deg, over, profile)
        return f"hand: {words[0]} to {degrees:g}° over {over:g} s"

    def _play(self, args: list[str]) -> str:
        from poppy_core.motion import read_move

        usage = "play FILE [--speed X]"
        words = list(args)
        speed = _take_option(words, "--speed", 1.0, usage, "--speed takes a factor")
        if len(words) != 1:
            raise ControlError(f"usage: {usage}")
        if not self.joints:
            raise ControlError("play needs --profile: a move names its motors")
        move = read_move(words[0])
        unknown = [m for m in move.motors if m not in self.joints]
        if unknown:
            raise ControlError(f"{words[0]}: motors not in the profile: {', '.join(unknown)}")
        if len(move) == 0:
            raise ControlError(f"{words[0]}: the move has no frame")
        columns = {}
        for name in move.motors:
            joint = self.joints[name]
            column = move.trajectory(name)
            columns[joint.id] = [
                to_motor(float(v), joint.orientation, joint.offset) for v in column
            ]
        duration = self.hand.play(move.times(), columns, speed)
        return f"hand: playing {words[0]} ({len(move.motors)} motors, {duration:g} s)"

    def _release(self, args: list[str]) -> str:
        if len(args) != 1:
            raise ControlError("usage: release ID|NAME|all")
        if args[0].lower() == "all":
            self.hand.release()
            return "hand: released all"
        motor_id, _ = self._joint(args[0])
        self.hand.release(motor_id)
        return f"hand: released {args[0]}"

    def _where(self) -> str:
        positions = self.hand.where()
        held = self.hand.holding()
        names = {j.id: (n, j) for n, j in self.joints.items()}
        parts = []
        for motor_id, degrees in sorted(positions.items()):
            if motor_id in names:
                name, joint = names[motor_id]
                user = to_user(degrees, joint.orientation, joint.offset)
                text = f"{name} {_degrees(user)}"
            else:
                text = f"{motor_id} {_degrees(degrees)}"
            parts.append(text + (" (held)" if motor_id in held else ""))
        return ", ".join(parts)


def joints_of(config: object) -> dict[str, HandJoint]:
    """The motors of a robot config (``RobotConfig.motors``) as joints by name."""
    motors = getattr(config, "motors", {})
    return {n: HandJoint(m.id, m.orientation, float(m.offset)) for n, m in motors.items()}


def _take_option(words: list[str], flag: str, default: float, usage: str, what: str) -> float:
    """``flag``'s number, removed from ``words`` with it (``default`` when it is not there)."""
    if flag not in words:
        return default
    at = words.index(flag)
    if at + 1 >= len(words):
        raise ControlError(f"usage: {usage}")
    value = _number(words[at + 1], what)
    del words[at : at + 2]
    return value


def _number(text: str, what: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise ControlError(f"{what}, not {text!r}") from None


def _degrees(value: float) -> str:
    """``12.3°``, and ``0.0°`` for a value that rounds to zero from below (not ``-0.0°``)."""
    text = f"{value:.1f}"
    return ("0.0" if text == "-0.0" else text) + "°"
