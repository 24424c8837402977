"""Every `--help` page: values named in words, no Python types, an Examples section that works.

The pages are those of the command tree as built, so a command added later is checked too (its
examples go in poppy_cli/examples.py).
"""

from __future__ import annotations

import re
import shlex
from typing import Any

import pytest

from poppy_cli.examples import EXAMPLES
from tests.helpers.cli_tree import parse, walk

PATHS = [path for path, _ in walk()]

PYTHON_TYPES = re.compile(
    r"<(bool|str|int|float|path|text|integer|list\[[^\]]*\]|\w+ range|[\w.]+\|[\w.|]+)>"
    r"|\blist\[(str|int|float)\]|\{[a-z_]+\}"
)


@pytest.mark.parametrize("path", PATHS, ids=lambda p: p or "poppy")
def test_help_page_names_values_in_words_and_has_examples(poppy: Any, path: str) -> None:
    result = poppy(*path.split(), "--help")
    assert result.code == 0, result.stderr
    page = result.stdout
    assert not PYTHON_TYPES.findall(page), PYTHON_TYPES.findall(page)
    assert "Examples" in page
    shown = [line.strip() for line in page.splitlines() if line.strip().startswith("$ poppy")]
    assert shown, page
    for line in shown:
        assert line.startswith(f"$ poppy {path}".rstrip()), line


def test_flags_show_no_value_and_options_a_word(poppy: Any) -> None:
    page = poppy("record", "--help").stdout
    assert re.search(r"--json\s+Print", page)  # was `--json <bool>`
    assert re.search(r"--force\s+-f\s+Replace", page)
    assert re.search(r"--duration\s+-d\s+SECONDS", page)
    assert "Usage: poppy record [OPTIONS] NAME" in page  # was {name}
    get = poppy("motor", "get", "--help").stdout
    assert "Usage: poppy motor get [OPTIONS] IDS REGISTERS..." in get
    assert "<list[str]>" not in get and "<int range>" not in get


@pytest.mark.parametrize("path", sorted(EXAMPLES), ids=lambda p: p or "poppy")
def test_examples_parse_as_they_are_written(path: str) -> None:
    """Each example runs the command it is listed under, with flags and arguments it accepts."""
    for line, _ in EXAMPLES[path]:
        words = shlex.split(line)
        parsed = parse(words)
        assert parsed.path, line  # a command ran (not just a group's help)
        if path:
            assert (parsed.path + " ").startswith(path + " "), (path, line, parsed.path)


def test_examples_are_given_for_every_command_and_only_those() -> None:
    assert set(EXAMPLES) == set(PATHS)


def test_poppy_help_groups_commands_by_task(poppy: Any) -> None:
    page = poppy("--help").stdout
    titles = ["Start here", "Set up", "Drive", "Moves", "Serve", "Simulate"]
    positions = [page.find(f"─ {title} ─") for title in titles]
    assert -1 not in positions and positions == sorted(positions), positions
    assert "─ Commands ─" not in page  # every command is in a panel
    root = dict(walk())[""]
    assert all(getattr(c, "rich_help_panel", None) for c in root.commands.values())
