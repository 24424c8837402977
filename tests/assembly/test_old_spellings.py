"""The previous release's spellings still work, each warning with the new one; the new ones are
quiet.

``poppy_core.robot.from_profile`` and ``poppy_core.creatures.PoppyErgoJr`` were the assembly's
names re-exported (by an import that climbed) from rooms below it; they now live at the top:
``poppy_core.from_profile`` and ``poppy_core.pypot.PoppyErgoJr``.
"""

from __future__ import annotations

import importlib
import subprocess
import sys
from pathlib import Path

import pytest

import poppy_core
import poppy_core.creatures
import poppy_core.pypot
import poppy_core.robot
from poppy_core.old_spellings import MOVED

ROOT = Path(__file__).resolve().parents[2]
OLD = sorted(
    (f"poppy_core.{room}", name, home)
    for room, names in MOVED.items()
    for name, home in names.items()
)


@pytest.mark.parametrize(("room", "name", "home"), OLD)
def test_an_old_spelling_warns_with_the_new_one_and_is_the_same_object(
    room: str, name: str, home: str
) -> None:
    module = importlib.import_module(room)
    with pytest.warns(DeprecationWarning, match=rf"{room}\.{name} .*: use {home}\.{name}$"):
        old = getattr(module, name)
    assert old is getattr(importlib.import_module(home), name)


def test_the_old_spellings_are_the_ones_issue_36_names() -> None:
    assert ("poppy_core.robot", "from_profile", "poppy_core") in OLD
    assert ("poppy_core.creatures", "PoppyErgoJr", "poppy_core.pypot") in OLD
    assert ("poppy_core.robot", "from_json", "poppy_core.pypot") in OLD


def test_the_rooms_do_not_hold_the_old_names() -> None:
    """The rooms define none of them (the package answers for them) and still refuse others."""
    for room, names in MOVED.items():
        module = importlib.import_module(f"poppy_core.{room}")
        assert not set(names) & set(vars(module)), room
        assert not set(names) & set(module.__all__), room
        with pytest.raises(AttributeError, match="has no attribute 'nothing_of_that_name'"):
            module.nothing_of_that_name  # noqa: B018


def _run(code: str) -> subprocess.CompletedProcess[str]:
    """``code`` in a fresh interpreter that turns every DeprecationWarning into an error."""
    return subprocess.run(
        [sys.executable, "-W", "error::DeprecationWarning", "-c", code],
        capture_output=True,
        text=True,
        cwd=ROOT,
        timeout=120,
    )


def test_the_old_import_lines_fail_under_warnings_as_errors_naming_the_new_one() -> None:
    creature = _run("from poppy_core.creatures import PoppyErgoJr")
    assert creature.returncode != 0
    assert "use poppy_core.pypot.PoppyErgoJr" in creature.stderr
    builder = _run("from poppy_core.robot import from_profile")
    assert builder.returncode != 0
    assert "use poppy_core.from_profile" in builder.stderr


def test_the_new_import_lines_are_quiet() -> None:
    code = (
        "from poppy_core import autodetect, from_config, from_profile, serve, ServeSpec, Listen\n"
        "from poppy_core.pypot import PoppyErgoJr, PoppyTorso, PoppyHumanoid, from_json\n"
        "from poppy_core.pypot import installed_poppy_creatures, from_remote\n"
        "import poppy_core.robot, poppy_core.creatures\n"
        "print(poppy_core.__version__)\n"
    )
    done = _run(code)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == poppy_core.__version__


def test_pypots_call_form_runs_on_the_old_spelling_too() -> None:
    """One release more, a script still on the old import line builds its robot."""
    with pytest.warns(DeprecationWarning, match="use poppy_core.pypot.PoppyErgoJr"):
        from poppy_core.creatures import PoppyErgoJr  # type: ignore[attr-defined]
    with PoppyErgoJr(simulator="dummy") as robot:
        assert [m.name for m in robot.motors] == ["m1", "m2", "m3", "m4", "m5", "m6"]
        assert robot.creature is not None and robot.creature.kind == "ergo-jr"
