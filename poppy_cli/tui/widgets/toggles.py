"""Check boxes and tick lists whose state is a mark, not only a colour: ``X`` ticked, blank not."""
# ruff: noqa: TID253  (the TUI package is only imported by `poppy tui`, lazily)

from __future__ import annotations

from typing import TypeVar

from rich.segment import Segment
from textual.content import Content
from textual.strip import Strip
from textual.widgets import Checkbox, SelectionList
from textual.widgets.option_list import OptionDoesNotExist

ON = "X"
OFF = " "
T = TypeVar("T")


class MarkedCheckbox(Checkbox):
    """A check box showing ``X`` when ticked and a blank when not (Textual's shows ``X`` in
    both states, only its colour changes)."""

    def render(self) -> Content:
        # ToggleButton draws BUTTON_INNER: set it for this box's state before drawing.
        self.BUTTON_INNER = ON if self.value else OFF
        return super().render()


class MarkedList(SelectionList[T]):
    """A tick list whose unticked rows show a blank box (``X`` for ticked rows only)."""

    def render_line(self, y: int) -> Strip:
        line = super().render_line(y)
        try:
            option = self.get_option_at_index(self.scroll_offset.y + y)
        except OptionDoesNotExist:
            return line
        if option.value in self.selected:
            return line
        # The box is the first three segments (left edge, mark, right edge): blank the mark.
        segments = list(line)
        if len(segments) > 1 and segments[1].text == ON:
            _, style, control = segments[1]
            segments[1] = Segment(OFF, style, control)
        return Strip(segments, line.cell_length)
