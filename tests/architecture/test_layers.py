"""The house plan holds: rooms import only the rooms below them, and start-up stays light."""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]

# room -> rooms of ours it may import (ARCHITECTURE.md); `errors`, `files` (safe writes),
# `documents` (bounded JSON/YAML reads), `line` (the byte-line contract and its URL schemes),
# `trajectory` (the pure maths of a goto, shared by Motor.goto_position and the primitives'
# sandbox), `checks` (the one rule of each kind of call argument) and `extras` (the optional
# dependencies, with the one-line error naming a missing extra) are leaves every room may use.
LEAVES = {"errors", "files", "documents", "line", "trajectory", "checks", "extras", "schedule"}
ALLOWED: dict[str, set[str]] = {
    "protocol": set(),
    "models": {"protocol"},
    "bus": {"protocol", "models"},
    "emulator": {"protocol", "models"},
    # cameras and marker detection: nothing of ours (OpenCV, numpy); renderers come from above
    "sensors": set(),
    # the MuJoCo plant of the emulator, in a room of its own (ARCHITECTURE: "poppy_core/sim/ if it
    # needs a room"); the robot factory builds it, as it builds emulators
    # sim's camera is a Sensor; its marker cards are drawn by sensors.markers
    "sim": {"emulator", "models", "protocol", "sensors"},
    # remote imports nothing of ours: pypot's from_remote is a robot factory returning its client
    "robot": {"bus", "models", "emulator", "sim", "protocol", "sensors", "remote"},
    # kinematics is a leaf (numpy only, nothing of ours but errors): rooms that need chains
    # import it, whatever their place in the plan's table
    "motion": {"robot", "models", "kinematics"},
    "creatures": {"robot", "motion", "models", "kinematics"},
    "kinematics": set(),
    "server": {"robot", "motion", "creatures", "models", "kinematics", "sensors"},
    "remote": set(),
}
# pypot's creature constructors start servers (use_http=True...): creatures/services.py, and only
# it, reaches the server room, inside functions (importing creatures loads no server library).
FILE_EXCEPTIONS = {
    ("creatures/services.py", "poppy_core.server.background"),
    ("creatures/services.py", "poppy_core.server.zmqserver"),
    ("creatures/services.py", "poppy_core.server.snap"),
}


def _imports(path: Path) -> set[str]:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    names: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names.add(node.module)
    return names


def test_rooms_import_only_downwards() -> None:
    bad = []
    for room, allowed in ALLOWED.items():
        for path in sorted((ROOT / "poppy_core" / room).rglob("*.py")):
            for name in _imports(path):
                parts = name.split(".")
                if parts[0] == "poppy_cli":
                    bad.append(f"{path.relative_to(ROOT)} imports {name}")
                if parts[0] != "poppy_core" or len(parts) < 2:
                    continue
                target = parts[1]
                if target == room or target in LEAVES or target in allowed:
                    continue
                local = path.relative_to(ROOT / "poppy_core").as_posix()
                if (local, name) in FILE_EXCEPTIONS:
                    continue
                bad.append(f"{path.relative_to(ROOT)} imports {name}")
    assert bad == []


def _module_level_imports(path: Path) -> set[str]:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    names: set[str] = set()
    for node in tree.body:
        if isinstance(node, ast.Import):
            names.update(alias.name.split(".")[0] for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names.add(node.module.split(".")[0])
    return names


def test_kinematics_is_numpy_only() -> None:
    """The kinematics room loads numpy and the standard library; mujoco only to read an MJCF."""
    found: set[str] = set()
    for path in (ROOT / "poppy_core" / "kinematics").rglob("*.py"):
        found |= _module_level_imports(path)
    ours = {"poppy_core", "__future__"}
    third_party = {n for n in found - ours if n not in sys.stdlib_module_names}
    assert third_party == {"numpy"}
    loaded = _loaded_after("import poppy_core.kinematics")
    assert not loaded & {"mujoco", "scipy", "typer", "rich", "pydantic", "serial"}


def test_leaves_import_only_errors_and_checks() -> None:
    for leaf in sorted(LEAVES):
        names = _imports(ROOT / "poppy_core" / f"{leaf}.py")
        ours = {n for n in names if n.split(".")[0] in ("poppy_core", "poppy_cli")}
        below = {"poppy_core.errors"} if leaf == "checks" else {"poppy_core.errors", "poppy_core"}
        # `from poppy_core import checks` is recorded as its package
        assert ours <= below, (leaf, ours)
        if "poppy_core" in ours:
            source = (ROOT / "poppy_core" / f"{leaf}.py").read_text(encoding="utf-8")
            assert "from poppy_core import checks" in source, leaf


def _loaded_after(code: str) -> set[str]:
    out = subprocess.run(
        [sys.executable, "-c", code + "\nimport sys\nprint('\\n'.join(sys.modules))"],
        capture_output=True,
        text=True,
        check=True,
        cwd=ROOT,
    ).stdout
    return {line.split(".")[0] for line in out.splitlines()}


def test_core_loads_no_ui_or_server_library() -> None:
    loaded = _loaded_after(
        "import poppy_core.protocol, poppy_core.models, poppy_core.bus.scan, "
        "poppy_core.emulator, poppy_core.robot"
    )
    assert not loaded & {
        "typer",
        "rich",
        "textual",
        "fastapi",
        "uvicorn",
        "mujoco",
        "matplotlib",
        "cv2",
    }


def test_cli_start_up_is_lazy() -> None:
    loaded = _loaded_after("import poppy_cli.main")
    assert not loaded & {"textual", "fastapi", "uvicorn", "mujoco", "matplotlib", "serial", "cv2"}
    assert "poppy_core" not in loaded or not {"numpy"} & loaded


@pytest.mark.parametrize("flag", ["--help", "--version"])
def test_help_does_not_import_heavy_libraries(flag: str) -> None:
    code = (
        "import sys\nfrom poppy_cli.main import app\n"
        f"try:\n    app([{flag!r}])\nexcept SystemExit:\n    pass\n"
    )
    loaded = _loaded_after(code)
    assert not loaded & {"textual", "fastapi", "uvicorn", "mujoco", "matplotlib", "cv2", "numpy"}


def test_trajectory_is_a_leaf_still_reachable_from_motion() -> None:
    """The goto maths loads no room (robot sits above it) and keeps its old import path."""
    from poppy_core import trajectory
    from poppy_core.motion import trajectory as old_path

    assert old_path.MinimumJerk is trajectory.MinimumJerk
    assert old_path.check_goto is trajectory.check_goto
    code = "import sys, poppy_core.trajectory\nprint('\\n'.join(sys.modules))"
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=ROOT
    ).stdout.split()
    ours = {name for name in out if name.startswith("poppy_core.")}
    assert ours <= {"poppy_core.trajectory", "poppy_core.errors", "poppy_core.checks"}, ours
