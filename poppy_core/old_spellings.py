"""The spellings of earlier releases, kept for one more: each warns and hands on the new one.

``poppy_core.robot.from_profile`` and ``poppy_core.creatures.PoppyErgoJr`` were the assembly's
names re-exported by the rooms below it, imports that climbed. The rooms no longer know them.
The package itself (``Package``, the class of ``poppy_core``) gives each of those rooms, when the
import system binds it on the package after it has run, a module ``__getattr__`` that answers
the old names with a ``DeprecationWarning`` naming the new spelling.
"""

from __future__ import annotations

import types
import warnings
from collections.abc import Callable, Mapping
from typing import Any

ROOT = "poppy_core"
PYPOT = "poppy_core.pypot"

MOVED: Mapping[str, Mapping[str, str]] = {
    "robot": {
        "autodetect": ROOT,
        "from_config": ROOT,
        "from_profile": ROOT,
        "from_json": PYPOT,
    },
    "creatures": {
        "from_config": ROOT,
        "from_profile": ROOT,
        "__version__": ROOT,
        "AbstractPoppyCreature": PYPOT,
        "PoppyErgoJr": PYPOT,
        "PoppyHumanoid": PYPOT,
        "PoppyTorso": PYPOT,
        "installed_poppy_creatures": PYPOT,
    },
}
"""Room of ``poppy_core`` -> old name -> the module that holds it now."""


class Package(types.ModuleType):
    """``poppy_core``: the rooms of ``MOVED`` answer their old names once bound on it."""

    def __setattr__(self, name: str, value: Any) -> None:
        super().__setattr__(name, value)
        moved = MOVED.get(name)
        if moved is not None and isinstance(value, types.ModuleType):
            vars(value).setdefault("__getattr__", _old_names(self, value.__name__, moved))


def _old_names(
    package: types.ModuleType, room: str, moved: Mapping[str, str]
) -> Callable[[str], Any]:
    def __getattr__(name: str) -> Any:
        home = moved.get(name)
        if home is None:
            raise AttributeError(f"module {room!r} has no attribute {name!r}")
        warnings.warn(
            f"{room}.{name} is an old spelling, removed in the next release: use {home}.{name}",
            DeprecationWarning,
            stacklevel=2,
        )
        if home == PYPOT:
            from poppy_core import pypot

            return getattr(pypot, name)
        return getattr(package, name)

    return __getattr__
