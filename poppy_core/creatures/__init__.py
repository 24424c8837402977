"""Creatures: what is specific to Poppy Ergo Jr, Torso and Humanoid (setup and primitives)."""

from types import MappingProxyType

from poppy_core import __version__
from poppy_core.creatures.body import DanceBeatMotion, HeadIdleMotion, UpperBodyIdleMotion
from poppy_core.creatures.ergo_jr import Dance, Jump, SafePowerUp
from poppy_core.creatures.face_tracking import FaceTracking
from poppy_core.creatures.factory import from_config, from_profile
from poppy_core.creatures.head_follow import HeadFollow
from poppy_core.creatures.interaction import ArmsCopyMotion, ArmsTurnCompliant
from poppy_core.creatures.postures import CreaturePosture
from poppy_core.creatures.pypot_creatures import (
    AbstractPoppyCreature,
    PoppyErgoJr,
    PoppyHumanoid,
    PoppyTorso,
)
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

installed_poppy_creatures = MappingProxyType(
    {"poppy-humanoid": PoppyHumanoid, "poppy-torso": PoppyTorso, "poppy-ergo-jr": PoppyErgoJr}
)
"""pypot's ``pypot.creatures.installed_poppy_creatures``: package name -> creature class (all three
are part of poppy)."""

__all__ = [
    "CREATURES",
    "AbstractPoppyCreature",
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
    "PoppyErgoJr",
    "PoppyHumanoid",
    "PoppyTorso",
    "SafePowerUp",
    "TemperatureMonitor",
    "TrackingFeedback",
    "UpperBodyIdleMotion",
    "__version__",
    "attach_creature",
    "detect_kind",
    "from_config",
    "from_profile",
    "installed_poppy_creatures",
    "normalize_kind",
]
