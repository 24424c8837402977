"""Every `poppy …` line of README.md and docs/*.md parses against the CLI (issue 40).

A line in a fenced code block that starts with ``poppy `` (after a ``$ `` prompt) is split as a
shell would, its comment, pipe, redirection or ``&`` dropped, and parsed by `poppy`'s own
command tree with every command's body replaced (``tests.helpers.cli_tree.parse``): the command
path must exist, its options exist and take the right number of values. Nothing runs.
"""

from __future__ import annotations

import itertools
import re
import shlex
from pathlib import Path

import pytest
from typer import _click as click

from tests.helpers import cli_tree

ROOT = Path(__file__).resolve().parents[2]
FILES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
FENCE = re.compile(r"^\s*(```|~~~)\s*(\w*)")
NOT_SHELL = {"python", "py", "json", "json5", "yaml", "toml", "ini", "xml", "html", "js"}
SHELL_END = {"|", "||", "&&", ";", "&", ">", ">>", "2>", "2>&1", "<"}
OPTIONAL = re.compile(r"\[([^\[\]]*)\]")  # a synopsis' [--flag VALUE] or [A | B]
ACTS = {"--install-completion", "--show-completion"}  # eager options that act when parsed
PLACEHOLDER = re.compile(r"^[A-Z][A-Z0-9_:]*$")  # a synopsis' NAME, N, HOST:PORT


def _code_lines(path: Path) -> list[tuple[int, str]]:
    """(line number, text) of the lines of shell code blocks, continued lines joined."""
    lines: list[tuple[int, str]] = []
    inside, shell, continued = False, False, False
    for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
        fence = FENCE.match(line)
        if fence:
            inside, continued = not inside, False
            shell = inside and fence.group(2).lower() not in NOT_SHELL
        elif shell and continued:  # a shell line continued with a backslash
            lines[-1] = (lines[-1][0], lines[-1][1][:-1] + " " + line.strip())
        elif shell:
            lines.append((number, line.rstrip()))
        continued = shell and line.rstrip().endswith("\\")
    return lines


def _synopsis(text: str) -> str:
    """A synopsis line as one command: each optional part kept, its first alternative taken."""
    while match := OPTIONAL.search(text):
        text = text[: match.start()] + match.group(1).split(" | ")[0] + text[match.end() :]
    return text.replace(" ...", "")


def _argvs(line: str) -> list[list[str]]:
    """The arguments after `poppy` of a shell line (one list per alternative of `a|b`)."""
    text = line.strip().removeprefix("$ ").strip().removeprefix("sudo ")
    if not text.startswith("poppy "):
        return []
    lexer = shlex.shlex(_synopsis(text), posix=True)
    lexer.whitespace_split = True
    lexer.commenters = "#"
    argv: list[str] = []
    for word in list(lexer)[1:]:
        if word in SHELL_END or word.startswith((">", "2>")):
            break
        argv.append(word.removesuffix(";").removesuffix("&"))
        if word.endswith((";", "&")):
            break
    variants = [[]]  # type: list[list[str]]
    for word in argv:
        choices = [word] if "|" not in word or "://" in word else word.split("|")
        variants = [[*v, choice] for v in variants for choice in choices]
    return variants


def doc_lines() -> list[tuple[str, list[str]]]:
    """Every documented `poppy` line: ("FILE:LINE", argv after `poppy`)."""
    found = []
    for path in FILES:
        for number, line in _code_lines(path):
            for argv in _argvs(line):
                found.append((f"{path.relative_to(ROOT)}:{number}", argv))
    return found


def _placeholder(error: click.exceptions.UsageError, argv: list[str]) -> bool:
    """Whether ``error`` refuses only a synopsis' placeholder (``--loop N``) for its type."""
    opts = getattr(getattr(error, "param", None), "opts", [])
    if not isinstance(error, click.exceptions.BadParameter):
        return False
    return any(w in opts and PLACEHOLDER.match(v) for w, v in itertools.pairwise(argv))


def test_the_docs_show_many_poppy_lines() -> None:
    assert len(doc_lines()) > 100


def test_every_documented_poppy_line_parses() -> None:
    wrong = []
    for where, argv in doc_lines():
        if ACTS.intersection(argv):
            continue
        try:
            cli_tree.parse(argv)
        except click.exceptions.NoArgsIsHelpError:
            pass  # a group alone: its help
        except click.exceptions.UsageError as error:
            if not _placeholder(error, argv):
                wrong.append(f"{where}: poppy {shlex.join(argv)}: {error.format_message()}")
    assert not wrong, "\n".join(wrong)


@pytest.mark.parametrize(
    ("line", "argv"),
    [
        ("$ poppy motor get 3  # the third motor", [["motor", "get", "3"]]),
        ("poppy serve --profile ergo-jr &", [["serve", "--profile", "ergo-jr"]]),
        ("poppy fleet status --json | jq .", [["fleet", "status", "--json"]]),
        ("sudo poppy record wave.json > out.txt", [["record", "wave.json"]]),
        ("poppy moves rm wave [--yes]", [["moves", "rm", "wave", "--yes"]]),
        ("poppy sim [--pty | --tcp H:P] [--view]", [["sim", "--pty", "--view"]]),
        ("poppy service take|release", [["service", "take"], ["service", "release"]]),
        ("pip install poppy", []),
    ],
)
def test_a_shell_line_becomes_poppy_s_arguments(line: str, argv: list[list[str]]) -> None:
    assert _argvs(line) == argv


def test_a_wrong_line_is_caught() -> None:
    for argv in (["fleet", "watch"], ["doctor", "--no-such-option"], ["motor", "set", "3"]):
        with pytest.raises(click.exceptions.UsageError):
            cli_tree.parse(argv)
