"""The house plan holds: rooms import only the rooms below them, and start-up stays light."""

from __future__ import annotations

import ast
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]

# room -> rooms of ours it may import (ARCHITECTURE.md); `errors`, `files` (safe writes),
# `documents` (bounded JSON/YAML reads), `line` (the byte-line contract and its URL schemes),
# `trajectory` (the pure maths of a goto, shared by Motor.goto_position and the primitives'
# sandbox), `checks` (the one rule of each kind of call argument) and `extras` (the optional
# dependencies, with the one-line error naming a missing extra) are leaves every room may use;
# so is `zenoh_wire` (the Zenoh keys, session settings and state message a served robot and its
# clients share, as `line` is the byte-line contract of buses and emulators), `zenoh_auth` (how
# those clients sign their messages and the robot checks them), `ros2_wire`
# (rmw_zenoh's keys, liveliness tokens and attachments, on top of `zenoh_wire`'s settings) and
# `zenoh_router` (the fleet's router, started by the CLI, on `zenoh_wire`'s settings).
LEAVES = {
    "errors",
    "files",
    "documents",
    "line",
    "trajectory",
    "checks",
    "extras",
    "schedule",
    "zenoh_wire",
    "zenoh_auth",
    "ros2_wire",
    "zenoh_router",
}
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
    "sim": {"emulator", "models", "protocol", "sensors", "kinematics"},
    # remote imports nothing of ours: pypot's from_remote is a robot factory returning its client
    "robot": {"bus", "models", "emulator", "sim", "protocol", "sensors", "remote", "kinematics"},
    # kinematics is a leaf (numpy only, nothing of ours but errors): rooms that need chains
    # import it, whatever their place in the plan's table
    # motion records episodes into the LeRobot format (a leaf room of floor 2)
    "motion": {"robot", "models", "kinematics", "dataset"},
    "creatures": {"robot", "motion", "models", "kinematics"},
    "kinematics": set(),
    # Foxglove writes a recorded dataset's episode as MCAP (`poppy dataset view --mcap`)
    "server": {"robot", "motion", "creatures", "models", "kinematics", "sensors", "dataset"},
    # Gymnasium environments on the simulation: a profile's MuJoCo world (robot, sim), its
    # chains (motion) stepped through the sim's servo model
    "learning": {"robot", "motion", "sim", "models", "kinematics"},
    "remote": set(),
    # the loop machinery, a package of leaves (pacing, worker, closing): nothing but the leaves
    "schedule": set(),
    # the LeRobot v3.0 format (pyarrow, PyAV): a leaf of the plan's floor 2, nothing of ours
    "dataset": set(),
}
# the composition root (floor 8): builds a robot with its creature, and its servers; every room
ALLOWED["assembly"] = set(ALLOWED)
# the top floor's faces (modules of the package itself): the package (``poppy_core.from_profile``
# ..., lazily), pypot's names (``poppy_core.pypot``) and the spellings of the last release
# (``old_spellings``, which the package loads first: the standard library only); they may import
# every room. Nothing below them imports them, nor the package itself (``import poppy_core``,
# ``from poppy_core import __version__``).
FACES = {"__init__", "pypot", "old_spellings"}
DYNAMIC_IMPORTERS = {"import_module", "__import__"}
# a room that imports a module whose name is computed: only the optional third-party libraries
EXTRAS_LOADER = "extras.py"
ENTRY_POINT = re.compile(r"poppy_core(\.[A-Za-z_][A-Za-z0-9_]*)+(:[A-Za-z_][A-Za-z0-9_.]*)?")


def _imports(path: Path) -> set[str]:
    return {name for name, _ in _imports_where(path)}


def _imports_where(path: Path) -> set[tuple[str, str]]:
    """Our modules ``path`` imports, each with the function it is imported in ("" at top level):
    import statements anywhere, ``importlib.import_module("...")`` / ``__import__("...")`` and
    entry points in strings (``"poppy_core.x.y:function"``), which climb just the same."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    found: set[tuple[str, str]] = set()

    def visit(node: ast.AST, where: str) -> None:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.If) and _type_checking_only(child):
                continue  # for the type checker only: never imported at run time
            inside = where
            if isinstance(child, ast.FunctionDef | ast.AsyncFunctionDef):
                inside = child.name if not where else f"{where}.{child.name}"
            if isinstance(child, ast.Import):
                found.update((alias.name, inside) for alias in child.names)
            elif isinstance(child, ast.ImportFrom) and child.module == "poppy_core":
                found.update((_of_the_package(alias.name), inside) for alias in child.names)
            elif isinstance(child, ast.ImportFrom) and child.module and child.level == 0:
                found.add((child.module, inside))
            elif isinstance(child, ast.Call) and _called(child.func) in DYNAMIC_IMPORTERS:
                first = child.args[0] if child.args else None
                if isinstance(first, ast.Constant) and isinstance(first.value, str):
                    found.add((first.value, inside))
                elif path.name != EXTRAS_LOADER:
                    found.add(("<a module named at run time>", inside))
            elif isinstance(child, ast.Constant) and ENTRY_POINT.fullmatch(str(child.value)):
                found.add((str(child.value).partition(":")[0], inside))
            visit(child, inside)

    visit(tree, "")
    return found


def _of_the_package(name: str) -> str:
    """``from poppy_core import NAME``: the module ``poppy_core.NAME``, or the package itself."""
    package = ROOT / "poppy_core"
    if (package / f"{name}.py").is_file() or (package / name / "__init__.py").is_file():
        return f"poppy_core.{name}"
    return "poppy_core"


def _type_checking_only(node: ast.If) -> bool:
    test = node.test
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING"
    )


def _called(func: ast.expr) -> str:
    if isinstance(func, ast.Attribute):
        return func.attr
    return func.id if isinstance(func, ast.Name) else ""


def _climbing(rooms: dict[str, set[str]]) -> list[str]:
    bad = []
    for room, allowed in rooms.items():
        for path in sorted((ROOT / "poppy_core" / room).rglob("*.py")):
            for name, where in sorted(_imports_where(path)):
                if name.startswith("<"):
                    bad.append(f"{path.relative_to(ROOT)} imports {name} in {where or 'its body'}")
                    continue
                parts = name.split(".")
                if parts[0] == "poppy_cli":
                    bad.append(f"{path.relative_to(ROOT)} imports {name}")
                if parts[0] != "poppy_core":
                    continue
                target = parts[1] if len(parts) > 1 else "__init__"
                if target == room or target in LEAVES or target in allowed:
                    continue
                inside = f" in {where}()" if where else ""
                bad.append(f"{path.relative_to(ROOT)} imports {name}{inside}")
    return bad


def test_rooms_import_only_downwards() -> None:
    """No room imports a higher one: at module level, in a function, or by an import string."""
    assert _climbing(ALLOWED) == []


def test_every_room_of_the_package_is_in_the_plan() -> None:
    rooms = {p.name for p in (ROOT / "poppy_core").iterdir() if (p / "__init__.py").is_file()}
    assert rooms <= set(ALLOWED), rooms - set(ALLOWED)


@pytest.mark.parametrize(
    "source",
    [
        "import importlib\nimportlib.import_module('poppy_core.creatures.attach')\n",
        "def f():\n    __import__('poppy_core.server.app')\n",
        "def f():\n    from poppy_core.creatures import registry\n",
        "HOOK = 'poppy_core.motion.manager:primitive_manager'\n",
        "import importlib\ndef f(name):\n    return importlib.import_module(name)\n",
        "import poppy_core\n",
        "from poppy_core import __version__\n",
        "def __getattr__(name):\n    from poppy_core import from_profile\n",
        "def __getattr__(name):\n    import poppy_core.assembly\n",
    ],
)
def test_the_layer_check_sees_every_way_of_climbing(
    source: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """An import string, a computed module name, a function-level import (a lazy re-export in
    a module's ``__getattr__`` too) and an import of the package itself all climb."""
    room = tmp_path / "poppy_core" / "robot"
    room.mkdir(parents=True)
    (room / "climber.py").write_text(source, encoding="utf-8")
    monkeypatch.setattr(sys.modules[__name__], "ROOT", tmp_path)
    assert len(_climbing({"robot": ALLOWED["robot"]})) == 1


def test_every_module_of_the_package_is_a_leaf_or_a_face() -> None:
    modules = {p.stem for p in (ROOT / "poppy_core").glob("*.py")}
    modules |= {p.parent.name for p in (ROOT / "poppy_core").glob("*/__init__.py")} & LEAVES
    assert modules == LEAVES | FACES, modules ^ (LEAVES | FACES)


def test_the_faces_import_only_poppy_core() -> None:
    for face in sorted(FACES):
        names = {n for n, _ in _imports_where(ROOT / "poppy_core" / f"{face}.py")}
        assert not {n for n in names if n.startswith(("poppy_cli", "<"))}, face


def test_the_package_loads_its_faces_on_first_use() -> None:
    """``import poppy_core`` (what every room's import runs first) loads no room: the faces
    import the assembly when first asked for, and are the assembly's."""
    out = subprocess.run(
        [sys.executable, "-c", "import sys, poppy_core\nprint('\\n'.join(sys.modules))"],
        capture_output=True,
        text=True,
        check=True,
        cwd=ROOT,
    ).stdout.split()
    assert {n for n in out if n.startswith("poppy_core")} == {
        "poppy_core",
        "poppy_core.old_spellings",
    }
    import poppy_core
    from poppy_core import assembly

    for name in poppy_core.FACES:
        assert getattr(poppy_core, name) is getattr(assembly, name)
    assert set(dir(poppy_core)) >= poppy_core.FACES
    with pytest.raises(AttributeError):
        poppy_core.nothing_of_that_name  # noqa: B018


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
        module = ROOT / "poppy_core" / f"{leaf}.py"  # a leaf is a module, or a package of them
        for path in [module] if module.is_file() else sorted((module.parent / leaf).glob("*.py")):
            names = _imports(path)
            ours = {n for n in names if n.split(".")[0] in ("poppy_core", "poppy_cli")}
            ours = {n for n in ours if not n.startswith(f"poppy_core.{leaf}")}  # its own modules
            below = {"poppy_core.errors"}
            if leaf != "checks":
                below |= {"poppy_core.checks"}
            if leaf in ("zenoh_wire", "zenoh_router"):  # a session needs the optional zenoh
                below |= {"poppy_core.extras"}
            if leaf == "zenoh_wire":  # a served robot's session checks its clients' signatures
                below |= {"poppy_core.zenoh_auth"}
            if leaf in ("ros2_wire", "zenoh_router"):  # the Zenoh session settings are the fleet's
                below |= {"poppy_core.zenoh_wire"}
            assert ours <= below, (leaf, path.name, ours)


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
    package = {"poppy_core.old_spellings"}  # the package's own, loaded first (standard library)
    assert ours <= {"poppy_core.trajectory", "poppy_core.errors", "poppy_core.checks"} | package
