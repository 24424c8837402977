"""Usage errors are one `error:` line with exit code 2; `--help` is untouched."""

from __future__ import annotations

from typing import Any

import pytest

CASES = [
    (("--baud", "0"), "No such option: --baud", "poppy --help"),
    (("robot", "goto"), "Missing argument 'TARGETS'", "poppy robot goto --help"),
    (("scan", "--baud", "fast"), "Invalid value for '--baud'", "poppy scan --help"),
    (("moves", "nonsense"), "No such command 'nonsense'", "poppy moves --help"),
    (
        ("robot", "goto", "m1=x", "--sim", "--profile", "ergo-jr"),
        "'x' is not a number",
        "poppy robot goto --help",
    ),
]


@pytest.mark.parametrize(("args", "message", "hint"), CASES, ids=[" ".join(c[0]) for c in CASES])
def test_usage_error_is_one_line(
    poppy: Any, args: tuple[str, ...], message: str, hint: str
) -> None:
    result = poppy(*args)
    assert result.code == 2
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    assert lines[0].startswith("error: ")
    assert message in lines[0]
    assert f"(see `{hint}`)" in lines[0]
    assert result.stdout == ""


def test_help_is_unchanged(poppy: Any) -> None:
    result = poppy("robot", "goto", "--help")
    assert result.code == 0
    assert result.stdout.lstrip().startswith("Usage: poppy robot goto [OPTIONS] TARGETS...")
    assert result.stderr == ""


def test_no_arguments_shows_the_help(poppy: Any) -> None:
    result = poppy("moves")
    assert "Usage: poppy moves" in result.stdout + result.stderr
    assert "error:" not in result.stderr
