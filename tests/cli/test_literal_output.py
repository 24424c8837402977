"""User text is printed as it is: no Rich markup, no emoji codes, no terminal control."""

from __future__ import annotations

import io
import json
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from poppy_cli.output import LiteralConsole, console, err_console, error_line, printable, styled
from tests.helpers.processes import reap
from tests.helpers.waiting import scaled

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
    from poppy_core import from_config

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


OSC_TITLE = "m\x1b]0;pwned\x07\x1b[41mX"  # sets the terminal's title, then paints it red


def test_a_warning_logged_with_a_motor_name_is_escaped(poppy: Any, tmp_path: Path) -> None:
    data = _config([OSC_TITLE, "m2"])
    data["controllers"]["bus"]["attached_motors"] = ["m2"]  # OSC_TITLE: "attached to none"
    path = tmp_path / "robot.json"
    path.write_text(json.dumps(data), encoding="utf-8")
    result = poppy("config", "validate", str(path))
    assert result.code == 0, result.stderr
    assert "motors.m\\x1b]0;pwned\\x07\\x1b[41mX is attached to no controller" in result.stderr
    assert "\x1b" not in result.stderr and "\x07" not in result.stderr


def test_the_log_formatter_escapes_records() -> None:
    import logging

    from poppy_cli.output import LiteralFormatter

    record = logging.LogRecord("x", logging.WARNING, __file__, 1, "host %s", ("a\x9bb",), None)
    assert LiteralFormatter("%(message)s").format(record) == "host a\\x9bb"


def test_text_built_by_the_caller_is_escaped_by_the_console(
    captured: tuple[io.StringIO, io.StringIO],
) -> None:
    from rich.table import Table
    from rich.text import Text

    _, err = captured
    err_console.print(Text.assemble(("warning:", "yellow"), " ", "a\x9b31mb \x1b[2J"))
    table = Table("name")
    table.add_row(Text("c\x9d0;t\x07"))
    err_console.print(table)
    shown = err.getvalue()
    assert "a\\x9b31mb \\x1b[2J" in shown
    assert "c\\x9" in shown  # the cell was measured on the raw text: its escape may be cut
    assert not any(char in shown for char in "\x9b\x9d\x1b\x07")


def test_the_servers_suggestion_never_writes_a_clients_control_characters() -> None:
    """C1 controls in a Host or Origin header reach `poppy serve`'s --allow-host/--cors hint."""
    import signal
    import socket
    import subprocess

    from tests.helpers.cli import POPPY, command_env

    proc = subprocess.Popen(
        [*POPPY, "serve", "--http", "--sim", "--profile", "ergo-jr", "--http-port", "0"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=dict(__import__("os").environ, **command_env()),
    )
    try:
        assert proc.stdout is not None and proc.stderr is not None
        url = proc.stdout.readline().strip()
        port = int(url.rsplit(":", 1)[1])
        requests = [
            b"GET /motors/list.json HTTP/1.1\r\nHost: ev\x9bil.com\r\nConnection: close\r\n\r\n",
            b"POST /api/v1/robot/compliant HTTP/1.1\r\nHost: 127.0.0.1\r\n"
            b"Origin: http://a\x9d31m.example\r\nContent-Length: 0\r\nConnection: close\r\n\r\n",
        ]
        for request in requests:
            with socket.create_connection(("127.0.0.1", port), timeout=10) as sock:
                sock.sendall(request)
                assert sock.recv(100).startswith(b"HTTP/1.1 4")
        proc.send_signal(signal.SIGTERM)
        assert proc.wait(timeout=scaled(30)) == 0
        err = proc.stderr.read()
    finally:
        reap(proc)
    assert "--allow-host ev\\x9bil.com" in err, err
    assert "--cors http://a\\x9d31m.example" in err, err
    assert "\x9b" not in err and "\x9d" not in err


def test_the_path_record_prints_for_scripts_is_escaped(
    poppy: Any, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("POPPY_MOVES_DIR", str(tmp_path / "moves"))
    target = tmp_path / f"take{ESCAPE}.move"
    result = poppy(
        "record",
        "w",
        "--sim",
        "--profile",
        "ergo-jr",
        "--motors",
        "m1",
        "--duration",
        "0.2",
        "--output",
        str(target),
    )
    assert result.code == 0, result.stderr
    assert target.is_file()
    assert result.stdout.strip().splitlines()[-1] == f"{tmp_path}/take\\x1b[2J.move"
    assert ESCAPE not in result.stdout
