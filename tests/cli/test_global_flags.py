"""`poppy --version` / `-V` and `poppy --quiet` / `-q`: flags of the root, meaning one thing."""

from __future__ import annotations

from collections.abc import Iterator
from importlib import metadata
from typing import Any

import pytest
import typer

from poppy_cli.main import app
from tests.helpers.cli import run_poppy


@pytest.mark.parametrize("flag", ["--version", "-V"])
def test_version(flag: str) -> None:
    result = run_poppy(flag)
    assert result.code == 0 and result.stderr == ""
    first, second, notice = result.stdout.splitlines()
    assert first == f"poppy {metadata.version('poppy')}"
    assert second.startswith("Python ") and "typer " in second
    assert "Poppy project" in notice and "CC BY-SA 4.0" in notice and "meshes/LICENSE" in notice


def _options(command: Any, path: str = "poppy") -> Iterator[tuple[str, str]]:
    for param in getattr(command, "params", []):
        for name in (*getattr(param, "opts", []), *getattr(param, "secondary_opts", [])):
            yield path, name
    for name, sub in getattr(command, "commands", {}).items():
        yield from _options(sub, f"{path} {name}")


def test_no_command_gives_the_root_flags_another_meaning() -> None:
    taken = {("-q", "--quiet"), ("-V", "--version")}
    used = [
        (path, name)
        for path, name in _options(typer.main.get_command(app))
        if path != "poppy" and any(name in pair for pair in taken)
    ]
    assert used == []


def test_quiet_prints_errors_only(ergo_jr: Any) -> None:
    port = ("--port", ergo_jr.url)
    loud = run_poppy("robot", "status", "--profile", "ergo-jr", *port, "--json")
    assert "warning: return delay" in loud.stderr  # the factory's 500 µs
    quiet = run_poppy("-q", "robot", "status", "--profile", "ergo-jr", *port, "--json")
    assert quiet.code == 0 and quiet.stderr == "" and len(quiet.json()["motors"]) == 6
    noted = run_poppy("--quiet", "motor", "set", "3", "goal_position", "30", *port)
    assert noted.code == 0 and noted.stderr == "" and "goal_position" in noted.stdout
    failed = run_poppy("-q", "motor", "get", "9", "present_position", *port, "--baud", "1000000")
    assert failed.code == 1 and failed.stderr.startswith("error: ") and "9" in failed.stderr


def test_quiet_goes_with_neither_verbose_nor_debug() -> None:
    for other in ("-v", "--debug"):
        result = run_poppy("-q", other, "ports")
        assert result.code == 2 and "--quiet" in result.stderr
