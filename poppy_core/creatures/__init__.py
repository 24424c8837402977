"""Creatures: what is specific to Poppy Ergo Jr, Torso and Humanoid (setup and primitives).

pypot's creature classes (``PoppyErgoJr``...), ``installed_poppy_creatures`` and the
``from_config`` / ``from_profile`` of earlier releases build robots and start servers: they are
the assembly's (``poppy_core.assembly``), re-exported here on first use by ``__getattr__`` (the
one import that climbs, by design: docs/internals.md, "The composition root").
"""

from typing import TYPE_CHECKING, Any

from poppy_core import __version__
from poppy_core.creatures.body import DanceBeatMotion, HeadIdleMotion, UpperBodyIdleMotion
from poppy_core.creatures.ergo_jr import Dance, Jump, SafePowerUp
from poppy_core.creatures.face_tracking import FaceTracking
from poppy_core.creatures.head_follow import HeadFollow
from poppy_core.creatures.interaction import ArmsCopyMotion, ArmsTurnCompliant
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

if TYPE_CHECKING:
    from poppy_core.assembly import (
        AbstractPoppyCreature,
        PoppyErgoJr,
        PoppyHumanoid,
        PoppyTorso,
        from_config,
        from_profile,
        installed_poppy_creatures,
    )

ASSEMBLED = frozenset(
    {
        "AbstractPoppyCreature",
        "PoppyErgoJr",
        "PoppyHumanoid",
        "PoppyTorso",
        "from_config",
        "from_profile",
        "installed_poppy_creatures",
    }
)
"""The names re-exported from the assembly."""


def __getattr__(name: str) -> Any:
    """The assembly's creature classes and builders, imported when first asked for."""
    if name in ASSEMBLED:
        import poppy_core.assembly

        return getattr(poppy_core.assembly, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


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
