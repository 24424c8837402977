"""Modal screens: edit one register value (checked with Register.from_si), confirm an action."""
# ruff: noqa: TID253  (the TUI package is only imported by `poppy tui`, lazily)

from __future__ import annotations

from typing import ClassVar

from textual import on
from textual.app import ComposeResult
from textual.binding import Binding, BindingType
from textual.containers import Horizontal, Vertical
from textual.screen import ModalScreen
from textual.widgets import Button, Input, Static

from poppy_cli.tui.busio import SIValue, parse_si
from poppy_core.errors import RegisterError
from poppy_core.models import Register


class EditValue(ModalScreen[SIValue | None]):
    """Ask a new value for a register, prefilled; Enter checks it, Escape cancels."""

    BINDINGS: ClassVar[list[BindingType]] = [Binding("escape", "cancel", "Cancel")]

    def __init__(self, register: Register, current: str, targets: int) -> None:
        super().__init__()
        self.register = register
        self.current = current
        self.targets = targets

    def compose(self) -> ComposeResult:
        reg = self.register
        allowed = reg.conversion.describe(reg.min_raw, reg.max_raw)
        where = f" on {self.targets} motors" if self.targets > 1 else ""
        with Vertical(classes="dialog"):
            yield Static(f"[b]{reg.name}[/] ({reg.memory}){where}", classes="title")
            yield Static(f"allowed: {allowed}", classes="hint")
            yield Input(self.current, id="edit-value")
            yield Static("", id="edit-error", classes="error")

    @on(Input.Submitted, "#edit-value")
    def _submit(self, event: Input.Submitted) -> None:
        try:
            value = parse_si(self.register, event.value)
        except RegisterError as exc:
            self.query_one("#edit-error", Static).update(str(exc))
            return
        self.dismiss(value)

    def action_cancel(self) -> None:
        """Close without writing."""
        self.dismiss(None)


class Confirm(ModalScreen[bool]):
    """Yes/no question (y / n keys, or the buttons)."""

    BINDINGS: ClassVar[list[BindingType]] = [
        Binding("y", "answer(True)", "Yes"),
        Binding("n,escape", "answer(False)", "No"),
    ]

    def __init__(self, question: str) -> None:
        super().__init__()
        self.question = question

    def compose(self) -> ComposeResult:
        with Vertical(classes="dialog"):
            yield Static(self.question, classes="title")
            with Horizontal(classes="buttons"):
                yield Button("Yes (y)", id="yes", variant="error")
                yield Button("No (n)", id="no", variant="primary")

    @on(Button.Pressed)
    def _pressed(self, event: Button.Pressed) -> None:
        self.dismiss(event.button.id == "yes")

    def action_answer(self, yes: bool) -> None:
        """Answer the question."""
        self.dismiss(yes)
