"""poppy_core: drive robots built from Robotis Dynamixel servos, real or emulated.

The package's faces build a robot and serve it: ``from_profile``, ``from_config``,
``autodetect`` and ``serve`` (with its ``ServeSpec`` and ``Listen``). They are the assembly's
(``poppy_core.assembly``, the floor above every room), imported on first use so that
``import poppy_core.bus`` loads no robot, creature or server. pypot's names (``PoppyErgoJr``,
``from_json``...) are in ``poppy_core.pypot``.
"""

import os
import sys
from typing import TYPE_CHECKING, Any

from poppy_core.old_spellings import Package

__version__ = "0.1.0"

# MuJoCo chooses its OpenGL backend once, when it is first imported, from MUJOCO_GL (glfw when
# unset, which needs a display). Without a display poppy renders offscreen with EGL; setting it
# here, before any room imports mujoco, makes every path (simulation, cameras, kinematics) agree.
if "MUJOCO_GL" not in os.environ and not os.environ.get("DISPLAY"):
    os.environ["MUJOCO_GL"] = "egl"

if TYPE_CHECKING:
    from poppy_core.assembly import Listen, ServeSpec, autodetect, from_config, from_profile, serve

__all__ = [
    "Listen",
    "ServeSpec",
    "__version__",
    "autodetect",
    "from_config",
    "from_profile",
    "serve",
]
FACES = frozenset(__all__) - {"__version__"}
"""The assembly's names the package hands on."""


def __getattr__(name: str) -> Any:
    """A face of the package: the assembly's builder of that name, imported when first asked for."""
    if name in FACES:
        import poppy_core.assembly

        return getattr(poppy_core.assembly, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    """The package's names with its faces (a notebook's tab completion offers them)."""
    return sorted({*globals(), *FACES})


sys.modules[__name__].__class__ = Package
