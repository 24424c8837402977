"""Names a newcomer can navigate: one class per name, and module names shared only on purpose.

Two classes of one name in two rooms (two ``Frame``, two ``Block``...) make every import, search
and traceback ambiguous; so do three ``teleop.py``. Classes are unique across ``poppy_core`` and
``poppy_cli``; a module's file name is unique in ``poppy_core`` too, except the pairs below, each
its room's own part of a common shape (a room's ``config``, ``spec``, ``routes``...). In
``poppy_cli`` a command and its TUI tab share their verb by design (``commands/scan.py``,
``tui/widgets/scan.py``).
"""

from __future__ import annotations

import ast
from collections import defaultdict
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PACKAGES = ("poppy_core", "poppy_cli")
SKIP = {"__init__.py", "__main__.py"}

SHARED_MODULE_NAMES = {
    "app.py": "server/app.py (the REST+WS app), server/snap/app.py (the Snap! app)",
    "base.py": "protocol/base.py (a protocol's contract), sensors/base.py (a sensor's)",
    "camera.py": "sensors/camera.py (a camera sensor), sim/camera.py (MuJoCo's rendering of it)",
    "imu.py": "sensors/imu.py (the IMUs and their frame), sim/imu.py (MuJoCo's IMU)",
    "catalog.py": "models/catalog.py (servo models), server/snap/catalog.py (Snap! blocks)",
    "config.py": "robot/config.py (the robot config), sensors/config.py (its sensors section)",
    "errors.py": "errors.py (the typed errors), server/errors.py (their HTTP mapping)",
    "motor.py": "robot/motor.py (Motor), emulator/motor.py (VirtualMotor)",
    "plant.py": "emulator/plant.py (an ideal servo), sim/plant.py (MuJoCo's)",
    "routes.py": "server/snap/routes.py (Snap!'s), server/web/routes.py (the web page's)",
    "trajectory.py": "trajectory.py (the leaf), motion/trajectory.py (its re-export for users)",
}


def _modules() -> list[Path]:
    return sorted(p for pkg in PACKAGES for p in (ROOT / pkg).rglob("*.py") if p.name not in SKIP)


def test_no_two_classes_share_a_name() -> None:
    """A module-level class name is defined once in poppy_core and poppy_cli."""
    where: dict[str, list[str]] = defaultdict(list)
    for path in _modules():
        for node in ast.parse(path.read_text(encoding="utf-8")).body:
            if isinstance(node, ast.ClassDef):
                where[node.name].append(str(path.relative_to(ROOT)))
    shared = {name: paths for name, paths in where.items() if len(paths) > 1}
    assert shared == {}


def test_module_names_are_shared_only_on_purpose() -> None:
    """Two modules of one file name are a listed pair (no second ``teleop.py`` or ``robot.py``)."""
    where: dict[str, list[str]] = defaultdict(list)
    for path in _modules():
        if path.relative_to(ROOT).parts[0] != "poppy_core":
            continue
        where[path.name].append(str(path.relative_to(ROOT)))
    shared = {name for name, paths in where.items() if len(paths) > 1}
    assert shared == set(SHARED_MODULE_NAMES)
