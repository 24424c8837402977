"""The composition root: the one place a robot is put together and its servers started.

The top room of ``poppy_core`` (it may import every other): ``from_config``, ``from_profile``,
``autodetect`` and pypot's ``from_json`` build a plain robot (``robot.factory``) and add its
primitive manager and creature; ``serve(robot, spec)`` builds every server of a robot around one
service; pypot's creature classes (``PoppyErgoJr(use_http=True)``) do both.
User code reaches them through the package's faces (``poppy_core.from_profile``...) and pypot's
names through ``poppy_core.pypot``.
"""

from types import MappingProxyType

from poppy_core.assembly.build import autodetect, from_config, from_json, from_profile
from poppy_core.assembly.pypot_creatures import (
    AbstractPoppyCreature,
    PoppyErgoJr,
    PoppyHumanoid,
    PoppyTorso,
)
from poppy_core.assembly.serve_spec import Listen, ServeSpec
from poppy_core.assembly.servers import Server, ServerSet, serve
from poppy_core.zenoh_wire import ZenohSettings

installed_poppy_creatures = MappingProxyType(
    {"poppy-humanoid": PoppyHumanoid, "poppy-torso": PoppyTorso, "poppy-ergo-jr": PoppyErgoJr}
)
"""pypot's ``pypot.creatures.installed_poppy_creatures``: package name -> creature class (all three
are part of poppy)."""

__all__ = [
    "AbstractPoppyCreature",
    "Listen",
    "PoppyErgoJr",
    "PoppyHumanoid",
    "PoppyTorso",
    "ServeSpec",
    "Server",
    "ServerSet",
    "ZenohSettings",
    "autodetect",
    "from_config",
    "from_json",
    "from_profile",
    "installed_poppy_creatures",
    "serve",
]
