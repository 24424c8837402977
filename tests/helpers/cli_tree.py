"""The `poppy` command tree for tests: every command; command lines parsed but not run."""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from functools import cache
from typing import Any

import typer.main
from typer import _click as click
from typer.core import TyperOption

from poppy_cli.main import app
from tests.helpers.cli import built_tree


def root() -> Any:
    """The root Click group of `poppy`, built as `poppy` builds it."""
    return typer.main.get_command(app)


def walk(command: Any | None = None, path: tuple[str, ...] = ()) -> Iterator[tuple[str, Any]]:
    """Every command and group: (path after `poppy`, e.g. "motor get"; "" for the root); the
    tree walked is ``command``'s, else `poppy`'s as built once (``built_tree``: read only)."""
    command = built_tree() if command is None else command
    yield " ".join(path), command
    for name, sub in getattr(command, "commands", {}).items():
        yield from walk(sub, (*path, name))


def options(command: Any) -> list[Any]:
    """The visible options of ``command``, its ``--help`` included."""
    params = [*command.params, command.get_help_option(click.Context(command))]
    return [p for p in params if isinstance(p, TyperOption) and not p.hidden]


@dataclass
class Parsed:
    """What a command line would run: the command's path and the values of its parameters."""

    path: str = ""
    params: dict[str, Any] = field(default_factory=dict)


def parse(args: Sequence[str]) -> Parsed:
    """Parse ``poppy ARGS`` as `poppy` does (root rewrites, types, option callbacks) but run no
    command: every command's body is replaced by one that records its parameters.

    Raises:
        click.exceptions.UsageError: the line does not parse.
    """
    tree, last = _recording_tree()
    last[:] = [Parsed()]
    tree.main(list(args), prog_name="poppy", standalone_mode=False)
    return last[0]


@cache
def _recording_tree() -> tuple[Any, list[Parsed]]:
    """A tree of `poppy` built once, each command's body replaced by one that records what it
    was given in the list returned with it."""
    last = [Parsed()]
    tree = root()
    for path, command in walk(tree):

        def record(__path: str = path, **params: Any) -> None:
            last[0] = Parsed(__path, params)

        command.callback = record
    return tree, last
