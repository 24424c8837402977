"""The whole control table of a motor as a DataTable; arrow keys turn the goal-position dial."""
# ruff: noqa: TID253  (the TUI package is only imported by `poppy tui`, lazily)

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from textual.binding import Binding, BindingType
from textual.message import Message
from textual.widgets import DataTable

from poppy_cli.output import shown_unit
from poppy_cli.tui.busio import RegisterRow, SIValue
from poppy_cli.tui.text import fixed, set_cell

COLUMNS = ("addr", "register", "value", "mem", "")


def format_value(value: SIValue | None, unit: str) -> str:
    """A register value for display: rounded floats, on/off booleans, the unit."""
    if value is None:
        return "?"
    if isinstance(value, bool):
        return "on" if value else "off"
    text = fixed(value) if isinstance(value, float) else str(value)
    return f"{text} {shown_unit(unit)}".rstrip()


class ControlTableView(DataTable[str]):
    """Address, name, SI value with unit, EEPROM/RAM, read-only mark. Enter edits a row."""

    BINDINGS: ClassVar[list[BindingType]] = [
        Binding("enter", "select_cursor", "Edit"),
        # The live panel shows the dial and its keys (←/→ ±1°, shift ±10°): no footer room.
        Binding("left", "dial(-1)", "Goal -1°", show=False),
        Binding("right", "dial(1)", "Goal +1°", show=False),
        Binding("shift+left", "dial(-10)", "-10°", show=False),
        Binding("shift+right", "dial(10)", "+10°", show=False),
    ]

    @dataclass
    class Dialled(Message):
        """The goal-position dial was turned by ``delta_deg``."""

        delta_deg: float

    def __init__(self, *, id: str | None = None) -> None:
        super().__init__(id=id, cursor_type="row", zebra_stripes=True)
        self.values: dict[str, RegisterRow] = {}

    def on_mount(self) -> None:
        for column in COLUMNS:
            self.add_column(column, key=column or "ro")

    def show(self, rows: list[RegisterRow]) -> None:
        """Fill the table (keeping the cursor row when the registers are the same)."""
        same = [row.register.name for row in rows] == list(self.values)
        self.values = {row.register.name: row for row in rows}
        if same:
            for row in rows:
                set_cell(self, row.register.name, "value", self._text(row))
            return
        cursor = self.cursor_row
        self.clear()
        for row in rows:
            reg = row.register
            self.add_row(
                str(reg.address),
                reg.name,
                self._text(row),
                reg.memory,
                "" if reg.writable else "ro",
                key=reg.name,
            )
        if rows:
            self.move_cursor(row=min(cursor, len(rows) - 1))

    def set_value(self, name: str, value: SIValue | None) -> None:
        """Show a new value for one register."""
        row = self.values.get(name)
        if row is None:
            return
        self.values[name] = RegisterRow(row.register, value)
        set_cell(self, name, "value", self._text(self.values[name]))

    @staticmethod
    def _text(row: RegisterRow) -> str:
        return format_value(row.value, row.register.unit)

    @property
    def current(self) -> RegisterRow | None:
        """The register under the cursor."""
        if not self.values or self.row_count == 0:
            return None
        key = self.coordinate_to_cell_key(self.cursor_coordinate).row_key.value
        return self.values.get(str(key))

    def action_dial(self, delta_deg: float) -> None:
        """Turn the goal-position dial."""
        self.post_message(self.Dialled(float(delta_deg)))
