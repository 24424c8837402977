"""The 29 primitives the Poppy creature packages attach in their ``setup()``, and their replay.

This module imports neither pypot nor poppy: the same replay runs on pypot 5.0.2 (the oracle,
``bench/.venv-peers``) and on poppy (``test_creature_packages.py``). Each entry is what the
package's ``setup()`` writes: the attribute name, the module under ``primitives/``, the class
and its arguments (``"robot"`` stands for the robot, ``"sound"`` for the package's sound file).
"""

from __future__ import annotations

import sys
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

PACKAGES = {
    "poppy-ergo-jr": ("poppy_ergo_jr", "4.0.2"),
    "poppy-torso": ("poppy_torso", "3.0.0"),
    "poppy-humanoid": ("poppy_humanoid", "3.0.0"),
}
"""Distribution -> (package, version): the versions of pypot 5.0.2's era on PyPI (the newest)."""

CLASSES = {
    "poppy-ergo-jr": "PoppyErgoJr",
    "poppy-torso": "PoppyTorso",
    "poppy-humanoid": "PoppyHumanoid",
}

RUN_S = 1.0
"""How long a primitive that does not end by itself runs before it is stopped."""

END_S = 60.0
"""How long a primitive may take to end (its own run, or its teardown after a stop)."""


@dataclass(frozen=True)
class Attached:
    """One ``robot.attach_primitive(Class(robot, *args), name)`` line of a creature's setup."""

    creature: str
    name: str
    module: str
    cls: str
    args: tuple[Any, ...] = ()
    kwargs: tuple[tuple[str, Any], ...] = ()
    ends: bool = False
    """It ends by itself (a posture): the replay waits for its end instead of stopping it."""


_ERGO = "poppy-ergo-jr"
_TORSO = "poppy-torso"
_HUMANOID = "poppy-humanoid"
_FR = "How_to_add_primitive_FR"

ATTACHED: tuple[Attached, ...] = (
    Attached(_ERGO, "safe_power_up", "postures", "SafePowerUp", ends=True),
    Attached(_ERGO, "dance", "dance", "Dance"),
    Attached(_ERGO, "base_posture", "postures", "BasePosture", (2.0,), ends=True),
    Attached(_ERGO, "rest_posture", "postures", "RestPosture", (2.0,), ends=True),
    Attached(_ERGO, "curious_posture", "postures", "CuriousPosture", (2.0,), ends=True),
    Attached(_ERGO, "tetris_posture", "postures", "TetrisPosture", (2.0,), ends=True),
    Attached(_ERGO, "tinsel_demo", _FR, "Tinsel"),
    Attached(_ERGO, "stubborn_demo", _FR, "Tetu"),
    Attached(_ERGO, "chicken_demo", _FR, "Poule"),
    Attached(_ERGO, "puzzel_demo", _FR, "Puzzel"),
    # attached by setup() on a real robot with a marker detector / a face detector
    Attached(_ERGO, "tracking_feedback", "tracking_feedback", "TrackingFeedback", (25.0,)),
    Attached(_ERGO, "face_detector", "face_tracking", "FaceTracking", (10, "face_detector")),
    Attached(_TORSO, "limit_torque", "safe", "LimitTorque", (), (("torque_max", 80),)),
    Attached(
        _TORSO, "temperature_monitoring", "safe", "TemperatureMonitor", (), (("sound", "sound"),)
    ),
    Attached(_TORSO, "dance_beat_motion", "dance", "SimpleBodyBeatMotion", (50,)),
    Attached(_TORSO, "init_position", "posture", "InitPosition", ends=True),
    Attached(_TORSO, "upper_body_idle_motion", "idle", "UpperBodyIdleMotion", (50,)),
    Attached(_TORSO, "head_idle_motion", "idle", "HeadIdleMotion", (50,)),
    Attached(_TORSO, "arms_turn_compliant", "interaction", "ArmsTurnCompliant", (50,)),
    Attached(_TORSO, "arms_copy_motion", "interaction", "PuppetMaster", (50,)),
    Attached(
        _HUMANOID, "temperature_monitoring", "safe", "TemperatureMonitor", (), (("sound", "sound"),)
    ),
    Attached(_HUMANOID, "stand_position", "posture", "StandPosition", ends=True),
    Attached(_HUMANOID, "sit_position", "posture", "SitPosition", ends=True),
    Attached(_HUMANOID, "limit_torque", "safe", "LimitTorque"),
    Attached(_HUMANOID, "dance_beat_motion", "dance", "SimpleBodyBeatMotion", (50,)),
    Attached(_HUMANOID, "upper_body_idle_motion", "idle", "UpperBodyIdleMotion", (50,)),
    Attached(_HUMANOID, "head_idle_motion", "idle", "HeadIdleMotion", (50,)),
    Attached(_HUMANOID, "arms_turn_compliant", "interaction", "ArmsTurnCompliant", (50,)),
    Attached(_HUMANOID, "arms_copy_motion", "interaction", "PuppetMaster", (50,)),
)

_SWAPPED = "TypeError: list indices must be integers or slices, not MockupMotor"

EXPECTED_FAILURES: dict[tuple[str, str], str] = {
    # What fails on pypot 5.0.2's dummy robots (this module run as the oracle, docs/pypot.md), and
    # fails the same way on poppy; every other primitive runs clean on pypot and must on poppy.
    # Built without a face detector (a simulated robot has none): its setup reads the detector.
    (_ERGO, "face_detector"): "AttributeError: 'NoneType' object has no attribute '_robot'",
    # The packages' teardown: `for m, i in enumerate(self.robot.motors)` swaps index and motor.
    (_TORSO, "limit_torque"): _SWAPPED,
    (_HUMANOID, "limit_torque"): _SWAPPED,
    # (tracking_feedback fails on pypot's dummy, which has no marker_detector: poppy's simulated
    # Ergo Jr has one, on its dummy camera, and it runs clean.)
}


def failure_name(exc: BaseException) -> str:
    """``Type: message`` of the exception at the root of ``exc`` (its cause chain)."""
    while exc.__cause__ is not None:
        exc = exc.__cause__
    return f"{type(exc).__name__}: {exc}"


def build(robot: Any, entry: Attached, classes: dict[str, Any], sound: str) -> Any:
    """The primitive as the creature's ``setup()`` builds it."""

    def value(item: Any) -> Any:
        if item == "sound":
            return sound
        if item == "face_detector":  # absent on a simulated robot, as on pypot's
            return getattr(robot, "face_detector", None)
        return item

    args = [value(a) for a in entry.args]
    kwargs = {k: value(v) for k, v in entry.kwargs}
    return classes[entry.cls](robot, *args, **kwargs)


def replay(
    robot: Any, entry: Attached, classes: dict[str, Any], sound: str, alive: Callable[[Any], bool]
) -> tuple[Any, list[str]]:
    """Build, attach, start, run (``RUN_S``, or to its end), stop: the primitive and the failures
    seen, in order.

    A failure is one line per exception raised by a call or in any thread (pypot's primitives
    die in their thread: ``threading.excepthook`` sees them); ``alive`` tells whether the
    primitive's thread still runs.
    """
    seen: list[str] = []
    primitive = None
    previous = threading.excepthook

    def hook(args: threading.ExceptHookArgs) -> None:
        if args.exc_value is not None:
            seen.append(failure_name(args.exc_value))

    threading.excepthook = hook
    try:
        primitive = build(robot, entry, classes, sound)
        robot.attach_primitive(primitive, f"pkg_{entry.name}")
        primitive.start()
        deadline = time.monotonic() + (END_S if entry.ends else RUN_S)
        while alive(primitive) and time.monotonic() < deadline:
            time.sleep(0.02)
        primitive.stop()
        deadline = time.monotonic() + END_S
        while alive(primitive) and time.monotonic() < deadline:
            time.sleep(0.02)
        if alive(primitive):
            seen.append(f"still running {END_S:g} s after stop()")
    except Exception as exc:
        seen.append(failure_name(exc))
    finally:
        threading.excepthook = previous
    return primitive, seen


def _oracle(folder: str) -> None:
    """Replay every primitive on pypot's dummy creatures (run by pypot's interpreter)."""
    import importlib
    import json
    import logging

    logging.disable(logging.CRITICAL)
    sys.path[:0] = [str(p) for p in sorted(Path(folder).iterdir())]
    import pypot.creatures  # noqa: F401  (first: importing a creature first leaves it unregistered)

    results: dict[str, list[str]] = {}
    for creature, (package, _) in PACKAGES.items():
        main = importlib.import_module(package)
        robot = getattr(main, CLASSES[creature])(simulator="dummy")
        sound = str(Path(main.__file__).parent / "media" / "sounds" / "error.wav")
        for entry in ATTACHED:
            if entry.creature != creature:
                continue
            module = importlib.import_module(f"{package}.primitives.{entry.module}")
            _, seen = replay(robot, entry, vars(module), sound, lambda p: p.is_alive())
            results[f"{creature} {entry.name}"] = seen
            print(f"{creature} {entry.name}: {seen or 'clean'}", file=sys.stderr, flush=True)
        robot.close()
    print(json.dumps(results, indent=1))


if __name__ == "__main__":  # bench/.venv-peers/bin/python creature_primitives.py <unpacked>
    _oracle(sys.argv[1])
