"""Creatures: what is specific to Poppy Ergo Jr, Torso and Humanoid (setup and primitives).

A robot is built with its creature by ``poppy_core.from_profile``...; pypot's creature classes
(``PoppyErgoJr``...), which build one and start its servers, are in ``poppy_core.pypot``.
"""

from poppy_core.creatures.body import DanceBeatMotion, HeadIdleMotion, UpperBodyIdleMotion
from poppy_core.creatures.ergo_jr import Dance, Jump, SafePowerUp
from poppy_core.creatures.face_tracking import FaceTracking
from poppy_core.creatures.head_follow import HeadFollow
from poppy_core.creatures.interaction import ArmsCopyMotion, ArmsTurnCompliant
from poppy_core.creatures.mimic import Mimic
from poppy_core.creatures.postures import CreaturePosture
from poppy_core.creatures.registry import (
    CREATURES,
    Creature,
    CreatureSpec,
    attach_creature,
    detect_kind,
    normalize_kind,
)
from poppy_core.creatures.safety import LimitTorque, TemperatureMonitor
from poppy_core.creatures.tracking import FollowInView, MarkerFollow, TrackingFeedback

__all__ = [
    "CREATURES",
    "ArmsCopyMotion",
    "ArmsTurnCompliant",
    "Creature",
    "CreaturePosture",
    "CreatureSpec",
    "Dance",
    "DanceBeatMotion",
    "FaceTracking",
    "FollowInView",
    "HeadFollow",
    "HeadIdleMotion",
    "Jump",
    "LimitTorque",
    "MarkerFollow",
    "Mimic",
    "SafePowerUp",
    "TemperatureMonitor",
    "TrackingFeedback",
    "UpperBodyIdleMotion",
    "attach_creature",
    "detect_kind",
    "normalize_kind",
]
