"""Display text for the TUI: numbers that never print a negative zero, cells that fit."""
# ruff: noqa: TID253  (the TUI package is only imported by `poppy tui`, lazily)

from __future__ import annotations

from rich.cells import cell_len
from textual.widgets import DataTable
from textual.widgets.data_table import ColumnKey


def fixed(value: float, digits: int = 1, width: int = 0) -> str:
    """``value`` with ``digits`` decimals, right-aligned in ``width``; -0.0 and what rounds to
    it (-0.04 at one decimal) print as 0."""
    text = f"{value:.{digits}f}"
    if text.startswith("-") and float(text) == 0.0:
        text = text[1:]
    return text.rjust(width)


def short(value: float) -> str:
    """``value`` in the shortest form (``{:g}``: 30, 2.5, 0.125); -0.0 prints as 0."""
    text = f"{value:g}"
    return "0" if text == "-0" else text


def set_cell(table: DataTable[str], row: str, column: str, text: str) -> None:
    """Show ``text`` in a cell, widening its column when it is longer (never cut: ``stopped``
    shown as ``stopp`` under a column sized for ``idle``); a column never shrinks back, so
    the columns do not shift as the values change."""
    shown = table.columns.get(ColumnKey(column))
    wider = shown is not None and cell_len(text) > shown.content_width
    table.update_cell(row, column, text, update_width=wider)
