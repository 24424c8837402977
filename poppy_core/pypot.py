"""pypot's names that build a robot, for code written for pypot: change the import line only.

``from pypot.creatures import PoppyErgoJr`` (or ``from poppy_ergo_jr import PoppyErgoJr``)
becomes ``from poppy_core.pypot import PoppyErgoJr``; ``pypot.robot``'s ``from_config``,
``from_json`` and ``from_remote`` are here too. ``PoppyErgoJr(simulator='poppy-simu')`` or
``PoppyErgoJr(use_http=True)`` then returns the running ``Robot`` with its creature and servers
(``poppy_core.assembly``); docs/pypot.md maps the rest of pypot's API.
"""

from poppy_core.assembly import (
    AbstractPoppyCreature,
    PoppyErgoJr,
    PoppyHumanoid,
    PoppyTorso,
    from_config,
    from_json,
    installed_poppy_creatures,
)
from poppy_core.robot.pypot_factories import from_remote

__all__ = [
    "AbstractPoppyCreature",
    "PoppyErgoJr",
    "PoppyHumanoid",
    "PoppyTorso",
    "from_config",
    "from_json",
    "from_remote",
    "installed_poppy_creatures",
]
