"""User text is printed as it is: no Rich markup, no emoji codes, no terminal control."""

from __future__ import annotations

import io
import json
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from poppy_cli.output import LiteralConsole, console, err_console, error_line, printable, styled

HOSTILE = "[red]m1:x:[/]"
ESCAPE = "\x1b[2J"


@pytest.fixture
def captured() -> Iterator[tuple[io.StringIO, io.StringIO]]:
    """The shared consoles, writing into strings (as a wide terminal with colours)."""
    out, err = io.StringIO(), io.StringIO()
    console.file, err_console.file = out, err
    try:
        yield out, err
    finally:  # None: back to following sys.stdout/sys.stderr, as the CLI's consoles do
        console.file = err_console.file = None  # type: ignore[assignment]


def _config(names: list[str]) -> dict[str, Any]:
    return {
        "controllers": {"bus": {"port": "auto", "protocol": 2, "attached_motors": names}},
        "motorgroups": {},
        "motors": {
            name: {"id": index, "type": "XL-320", "angle_limit": [-90, 90]}
            for index, name in enumerate(names, start=1)
        },
    }


def test_printable_escapes_terminal_control_only() -> None:
    assert printable("m1 [red] :x: é\tb\nc") == "m1 [red] :x: é\tb\nc"
    assert printable(f"a{ESCAPE}b") == "a\\x1b[2Jb"
    assert printable("x\u202ey") == "x\\u202ey"


def test_styled_keeps_its_markup_and_shows_values_literally() -> None:
    text = styled("[green]ok[/] {}: {}", HOSTILE, f"end\\{ESCAPE}")
    assert text.plain == f"ok {HOSTILE}: end\\\\x1b[2J"
    assert any(span.style == "green" for span in text.spans)


def test_error_line_is_one_literal_line(captured: tuple[io.StringIO, io.StringIO]) -> None:
    _, err = captured
    error_line(f"no motor {HOSTILE}\nin {ESCAPE}:smile:")
    assert err.getvalue() == f"error: no motor {HOSTILE}\\nin \\x1b[2J:smile:\n"


def test_tables_and_status_show_motor_names_literally() -> None:
    from poppy_cli.commands.robot import status_table
    from poppy_core.robot import from_config

    out = io.StringIO()
    wide = LiteralConsole(file=out, width=240, force_terminal=True, color_system=None)
    names = [HOSTILE, f"e{ESCAPE}", "[bold]b"]
    with from_config(_config(names), sim=True) as robot:
        wide.print(status_table(robot, title=f"robot {HOSTILE}"))
    shown = out.getvalue()
    assert f"robot {HOSTILE}" in shown
    assert HOSTILE in shown and "[bold]b" in shown and "e\\x1b[2J" in shown
    assert "❌" not in shown and ESCAPE not in shown


def test_scan_and_play_progress_read_no_markup() -> None:
    import inspect

    from poppy_cli.commands import play, scan

    for module in (play, scan):
        source = inspect.getsource(module)
        assert 'TextColumn("{task.description}", markup=False)' in source


def test_validate_etc_passwd_shows_its_text(poppy: Any) -> None:
    result = poppy("config", "validate", "/etc/passwd")
    assert result.code == 1
    assert "root:x:0:0" in result.stderr
    assert "❌" not in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1


def test_hostile_motor_names_in_show_and_errors(poppy: Any, tmp_path: Path) -> None:
    folder = tmp_path / "[bold]cfg:x:"
    folder.mkdir()
    path = folder / "robot.json"
    path.write_text(json.dumps(_config([HOSTILE, "m2"])), encoding="utf-8")
    shown = poppy("config", "show", str(path))
    assert shown.code == 0, shown.stderr
    assert HOSTILE in shown.stdout and "[bold]cfg:x:" in shown.stdout
    data = _config([HOSTILE, "m2"])
    data["motors"][HOSTILE]["angle_limit"] = [90, -90]
    path.write_text(json.dumps(data), encoding="utf-8")
    result = poppy("config", "validate", str(path))
    assert result.code == 1
    assert f"{folder}/robot.json: motors.{HOSTILE}.angle_limit" in result.stderr
    missing = poppy("config", "validate", str(tmp_path / f"no{ESCAPE}[red]file.json"))
    assert "no\\x1b[2J[red]file.json" in missing.stderr
    assert ESCAPE not in missing.stderr
