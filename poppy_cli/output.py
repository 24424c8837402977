"""Shared console helpers: Rich on stdout, errors on stderr, JSON for scripts.

Text is printed literally: the consoles read no Rich markup and no ``:emoji:`` codes, so a file,
port, motor or move name is shown as it is (``/etc/passwd``'s ``root:x:0:0`` stays text, a motor
named ``[red]x`` restyles nothing), and control characters (terminal escapes, bidi overrides)
are shown as ``\x1b``-style escapes instead of acting on the terminal. Our own styling goes
through ``styled``, which escapes the values it is given. The two ways text reaches the terminal
each escape once, whatever the caller built: the consoles every piece of text they render
(a string, a ``Text``, a table cell), and the log handler (``log_to_stderr``) every record.
"""

from __future__ import annotations

import json
import logging
import sys
import unicodedata
from collections.abc import Iterable
from typing import Any

from rich.cells import cell_len
from rich.console import Console, ConsoleDimensions, ConsoleOptions, RenderableType
from rich.markup import escape
from rich.segment import Segment
from rich.table import Table
from rich.text import Text

EXIT_OK = 0
EXIT_FAILURE = 1
EXIT_USAGE = 2
EXIT_INTERRUPTED = 130

PIPED_WIDTH = 100_000
"""The width of a console whose output is not a terminal: a table takes the width of its data
and a line is never wrapped, so what a pipe or a file gets is whole lines, never cut."""

_KEPT = frozenset("\n\t")
_BIDI = frozenset("\u202a\u202b\u202c\u202d\u202e\u2066\u2067\u2068\u2069")


def printable(text: str) -> str:
    """``text`` with control characters (but newlines and tabs) and bidi overrides escaped."""
    if text.isprintable():
        return text
    return "".join(
        char.encode("unicode_escape").decode("ascii")
        if (unicodedata.category(char) == "Cc" and char not in _KEPT) or char in _BIDI
        else char
        for char in text
    )


class LiteralConsole(Console):
    """A Rich console that prints every string as it is: no markup, no emoji, no highlighting,
    no terminal control (see ``printable``); styled output is built with ``styled``.

    Piped (its file is not a terminal), it is as wide as the data (``PIPED_WIDTH``): tables are
    never cut to 80 columns nor a value wrapped over two lines, whatever ``COLUMNS`` says, and
    a live display ends its last frame with a newline.
    """

    def __init__(self, **options: Any) -> None:
        super().__init__(markup=False, emoji=False, highlight=False, **options)

    @property
    def size(self) -> ConsoleDimensions:
        """The terminal's size; ``PIPED_WIDTH`` wide when the output is not a terminal."""
        size = Console.size.fget(self)  # type: ignore[attr-defined]
        assert isinstance(size, ConsoleDimensions)
        if self.is_terminal:
            return size
        return ConsoleDimensions(PIPED_WIDTH, size.height)

    @size.setter
    def size(self, new_size: tuple[int, int]) -> None:
        Console.size.fset(self, new_size)  # type: ignore[attr-defined]

    def pop_render_hook(self) -> None:
        """Rich ends a live display with a newline on a terminal only: piped, its last frame
        (which it does print) ran into the next line (``└──┘replayed 135 frames``)."""
        from rich.live import Live

        hook = self._render_hooks[-1] if self._render_hooks else None
        super().pop_render_hook()
        if (
            isinstance(hook, Live)
            and not hook.transient
            and not self.is_terminal
            and hook._live_render.last_render_height
        ):
            self.line()

    def render_str(self, text: str, **options: Any) -> Text:
        """Every string printed, in a table cell, a title or a status, passes here."""
        options.update(markup=False, emoji=False)
        return super().render_str(printable(text), **options)

    def render(
        self, renderable: RenderableType, options: ConsoleOptions | None = None
    ) -> Iterable[Segment]:
        """Every piece of text rendered passes here, a ``Text`` built by the caller included
        (``Text.assemble(..., line)`` skips ``render_str``): its control characters are
        escaped; the console's own control segments (cursor moves of a live display) are kept.
        Piped, a table is made as wide as its title, which would wrap otherwise.
        """
        if isinstance(renderable, Table) and not self.is_terminal and renderable.title:
            title = renderable.title
            wide = title.cell_len if isinstance(title, Text) else cell_len(str(title))
            renderable.min_width = max(renderable.min_width or 0, wide)
        for segment in super().render(renderable, options):
            if segment.control is None and not segment.text.isprintable():
                yield Segment(printable(segment.text), segment.style)
            else:
                yield segment


console = LiteralConsole()
err_console = LiteralConsole(stderr=True)


def styled(template: str, *values: object) -> Text:
    """Our Rich markup ``template`` with ``values`` put in its ``{}`` literally.

    ``styled("[green]ok[/] {}: {} motors", path, count)``: the template is ours and may carry
    markup; each value is shown as text, whatever brackets, colons or control characters it
    holds.
    """
    shown = (escape(printable(str(value))) for value in values)
    return Text.from_markup(template.format(*shown), emoji=False)


def plain(text: object) -> Text:
    """``text`` as a Rich ``Text`` shown literally (for widgets that would read markup in a
    string: a status spinner, a progress column)."""
    return Text(printable(str(text)))


def _tidy(data: Any) -> Any:
    """``data`` with ``-0.0`` written ``0.0`` (a motor at rest reads ``-0.0`` after a sign flip)."""
    if isinstance(data, float):
        return data + 0.0
    if isinstance(data, dict):
        return {key: _tidy(value) for key, value in data.items()}
    if isinstance(data, list | tuple):
        return [_tidy(value) for value in data]
    return data


def print_json(data: Any) -> None:
    """Write `data` as JSON on stdout, nothing else (the shapes: docs/cli.md, JSON output)."""
    sys.stdout.write(json.dumps(_tidy(data), indent=2, default=str) + "\n")
    sys.stdout.flush()


def error_line(message: str) -> None:
    """Print one clear error line on stderr (``message`` literally, on one line), even with
    `--quiet` (which quiets ``err_console`` for everything else)."""
    one_line = message.replace("\r", "\\r").replace("\n", "\\n")
    quiet, err_console.quiet = err_console.quiet, False
    try:
        err_console.print(styled("[bold red]error:[/] {}", one_line), soft_wrap=True)
    finally:
        err_console.quiet = quiet


def warn_line(message: str) -> None:
    """Print one warning line on stderr (``message`` literally; not with `--quiet`)."""
    err_console.print(styled("[yellow]warning:[/] {}", message), soft_wrap=True)


def note_line(message: str) -> None:
    """Print one note on stderr (``message`` literally; not with `--quiet`): something the
    user may not expect, and what to do about it."""
    err_console.print(styled("[cyan]note:[/] {}", message), soft_wrap=True)


class LiteralFormatter(logging.Formatter):
    """A log formatter that escapes control characters (see ``printable``): a log line quotes
    what users and clients sent (a motor name of a config, an ``Origin`` header)."""

    def format(self, record: logging.LogRecord) -> str:
        """The record as the base formatter writes it, control characters escaped."""
        return printable(super().format(record))


class _StderrHandler(logging.StreamHandler):  # type: ignore[type-arg]
    """Writes to whatever ``sys.stderr`` is when a record comes (as Python's last resort)."""

    @property
    def stream(self) -> Any:
        return sys.stderr

    @stream.setter
    def stream(self, value: Any) -> None:
        del value


def log_to_stderr(level: int = logging.WARNING, fmt: str = "%(message)s") -> None:
    """Send the records of ``level`` and above to stderr through ``LiteralFormatter``.

    The CLI calls it once at start: WARNING and above by default (what Python's last-resort
    handler showed, now escaped), INFO with ``-v``, DEBUG with ``--debug``.
    """
    root = logging.getLogger()
    for old in [h for h in root.handlers if isinstance(h, _StderrHandler)]:
        root.removeHandler(old)
    handler = _StderrHandler()
    handler.setFormatter(LiteralFormatter(fmt))
    handler.setLevel(level)
    root.addHandler(handler)
    if root.level > level or root.level == logging.NOTSET:
        root.setLevel(level)


def counted(count: int, noun: str) -> str:
    """``1 controller``, ``2 controllers``, ``0 controllers``: ``noun`` is a regular noun."""
    return f"{count} {noun}" if count == 1 else f"{count} {noun}s"


SHOWN_UNITS = {"deg": "°", "deg/s": "°/s"}
"""Units as people read them: registers say ``deg`` (and JSON keeps it), tables and lines ``°``."""


def shown_unit(unit: str) -> str:
    """``unit`` as shown to people: ``°`` for ``deg``, ``°/s`` for ``deg/s``, others as they are."""
    return SHOWN_UNITS.get(unit, unit)


def fmt_deg(value: float, step_deg: float = 0.1, unit: str = "°") -> str:
    """Degrees as the CLI prints them: the decimals of ``step_deg`` (a motor's resolution,
    ``poppy_core.models.degrees.tick_deg``), never ``-0``."""
    from poppy_core.models.degrees import fmt_deg as core_fmt_deg

    return core_fmt_deg(value, step_deg, unit)


def fmt_value(value: Any, unit: str = "") -> str:
    """Format an SI register value with its unit for humans (``30 °``, ``4.5 V``, ``on``)."""
    unit = shown_unit(unit)
    if isinstance(value, bool):
        return "on" if value else "off"
    if isinstance(value, float):
        text = f"{value:.2f}".rstrip("0").rstrip(".") if abs(value) < 1e6 else f"{value:.0f}"
        if text == "-0":
            text = "0"
    else:
        text = str(value)
    return f"{text} {unit}".strip() if unit else text
