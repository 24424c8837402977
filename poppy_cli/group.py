"""The root group of `poppy`: old flag spellings, and help pages in words rather than types.

Typer shows ``<bool>`` after an on/off flag, Python types as values (``<int range>``,
``<list[str]>``) and arguments as ``{name}``. Once the command tree is built, ``polish_help``
gives every option the value name of ``poppy_cli.flags`` (``--duration SECONDS``), flags none,
arguments their name in capitals (``NAME``, ``[NAME]``, ``REGISTERS...``), and every command the
Examples section of ``poppy_cli.examples``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from typer._click import Context
from typer.core import TyperArgument, TyperGroup, TyperOption

from poppy_cli.examples import examples_epilog
from poppy_cli.flags import FLAGS, rewrite_deprecated
from poppy_cli.options import SimArgsGroup, command_path
from poppy_cli.output import warn_line

if TYPE_CHECKING:
    from typer import _click


class WordArgument(TyperArgument):
    """An argument shown by its name in capitals: ``NAME``, ``[NAME]``, ``NAMES...``."""

    def _usage_display_name(self) -> str:
        return self.display_name_raw if self.required else f"[{self.display_name_raw}]"

    def _rich_display_name(self) -> str:
        return self.display_name_raw

    def display_type_rich(self, ctx: _click.Context) -> str | None:
        """No type column: the name and the help say what to give."""
        return None

    def get_error_hint(self) -> str:
        """``'NAME'`` as the usage line shows it (without ``...``)."""
        return f"'{self.display_name_raw.removesuffix('...')}'"


def option_value_name(option: TyperOption) -> str:
    """What the help shows after a value option: the table's value name, else its own name."""
    for name in option.opts:
        flag = FLAGS.get(name)
        if flag is not None and flag.value is not None:
            return flag.value
    return option.name.upper()


def polish_param(param: Any) -> None:
    """Give ``param`` a word for its value (none for an on/off flag) instead of a Python type."""
    if isinstance(param, TyperOption):
        if param.is_flag or param.count:
            param.metavar = ""  # Typer would show <bool>
        elif param.metavar is None:
            param.metavar = option_value_name(param)
    elif isinstance(param, TyperArgument) and not isinstance(param, WordArgument):
        if param.metavar is None:
            param.metavar = param.name.upper() + ("..." if param.nargs != 1 else "")
        param.__class__ = WordArgument


def polish_help(command: Any, path: tuple[str, ...] = ()) -> None:
    """Give ``command`` and its subcommands word metavars and their Examples section."""
    help_option = command.get_help_option(Context(command))  # made once, kept by the command
    for param in [*command.params, help_option]:
        polish_param(param)
    if getattr(command, "epilog", None) is None:
        command.epilog = examples_epilog(" ".join(path))
    for name, sub in getattr(command, "commands", {}).items():
        polish_help(sub, (*path, name))


class PoppyGroup(SimArgsGroup):
    """The root group: ``--sim [ENGINE]`` (``SimArgsGroup``), deprecated spellings, help pages."""

    def __init__(self, **attrs: Any) -> None:
        super().__init__(**attrs)
        polish_help(self)

    def get_params(self, ctx: _click.Context) -> list[_click.Parameter]:
        """The root's parameters, with those Typer adds after building it (completion) polished."""
        params = super().get_params(ctx)
        for param in params:
            polish_param(param)
        return params

    def parse_args(self, ctx: _click.Context, args: list[str]) -> list[str]:
        """Rewrite the deprecated spellings of the command about to run (a warning each)."""
        path = _command_path(self, ctx, args)
        if path:
            args, notes = rewrite_deprecated(path, args)
            if not ctx.resilient_parsing:  # not while completing
                for note in notes:
                    warn_line(note)
        return super().parse_args(ctx, args)


def _command_path(group: TyperGroup, ctx: _click.Context, args: list[str]) -> tuple[str, ...]:
    """The words naming the (sub)command ``args`` runs, e.g. ``("motor", "reset")``."""
    return tuple(command_path(group, ctx, args)[0])
