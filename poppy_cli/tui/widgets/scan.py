"""Scan options (protocol, baud rates, ID range), Scan/Abort buttons and the progress bar."""
# ruff: noqa: TID253  (the TUI package is only imported by `poppy tui`, lazily)

from __future__ import annotations

from dataclasses import dataclass

from textual import on
from textual.app import ComposeResult
from textual.containers import Horizontal, Vertical
from textual.message import Message
from textual.widgets import Button, Input, ProgressBar, Select, SelectionList, Static
from textual.widgets.selection_list import Selection

from poppy_cli.tui.widgets.toggles import MarkedList
from poppy_core.models import standard_baudrates

ALL_RATES = sorted(set(standard_baudrates(1)) | set(standard_baudrates(2)), reverse=True)
PROTOCOL_CHOICES = [("protocol 1 + 2", "both"), ("protocol 1", "1"), ("protocol 2", "2")]


@dataclass(frozen=True)
class ScanRequest:
    """What to scan: baud rates, protocols and the ID range (ports come from the ports panel)."""

    baudrates: tuple[int, ...]
    protocols: tuple[int, ...]
    ids: range


class ScanPanel(Vertical):
    """Protocol choice, baud-rate checkboxes, ID range, Scan/Abort and progress."""

    @dataclass
    class Requested(Message):
        """The user asked for a scan (``request`` None: abort)."""

        request: ScanRequest | None

    def compose(self) -> ComposeResult:
        yield Select(PROTOCOL_CHOICES, value="both", allow_blank=False, id="protocol")
        yield Static("Baud rates [dim](space ticks)[/]", classes="title")
        yield MarkedList[int](
            *(Selection(f"{rate:>9,} bps", rate, rate == 1_000_000) for rate in ALL_RATES),
            id="bauds",
        )
        with Horizontal(id="id-range"):
            yield Static("IDs", classes="label")
            yield Input("0", id="id-from", type="integer", max_length=3)
            yield Input("253", id="id-to", type="integer", max_length=3)
        with Horizontal(id="scan-buttons"):
            yield Button("Scan", id="scan", variant="primary")
            yield Button("Abort", id="abort", variant="error", disabled=True)
        yield ProgressBar(total=1, show_eta=False, id="scan-progress")
        yield Static("", id="scan-status")

    def set_choice(self, baudrates: list[int] | None, protocols: list[int] | None) -> None:
        """Preset the options (``--baud``/``--protocol``); None keeps all rates / both."""
        bauds = self.query_one("#bauds", SelectionList)
        if baudrates is None:
            bauds.select_all()
        else:
            bauds.deselect_all()
            for rate in baudrates:
                if rate not in ALL_RATES:
                    bauds.add_option(Selection(f"{rate:>9,} bps", rate, True))
                bauds.select(rate)
        choice = "both" if protocols is None or len(protocols) != 1 else str(protocols[0])
        self.query_one("#protocol", Select).value = choice

    def request(self) -> ScanRequest | str:
        """The scan the options describe, or a readable reason they are not valid."""
        rates = tuple(self.query_one("#bauds", SelectionList).selected)
        if not rates:
            return "tick at least one baud rate"
        choice = self.query_one("#protocol", Select).value
        protocols = (1, 2) if choice == "both" else (int(str(choice)),)
        try:
            low = int(self.query_one("#id-from", Input).value or 0)
            high = int(self.query_one("#id-to", Input).value or 253)
        except ValueError:
            return "the ID range takes numbers 0-253"
        if not 0 <= low <= high <= 253:
            return "the ID range must be within 0-253, from <= to"
        return ScanRequest(rates, protocols, range(low, high + 1))

    def running(self, on_: bool) -> None:
        """Enable Abort while scanning, Scan otherwise."""
        self.query_one("#scan", Button).disabled = on_
        self.query_one("#abort", Button).disabled = not on_

    def show_progress(self, done: int, total: int, text: str) -> None:
        """Move the progress bar and say where the scan is."""
        self.query_one("#scan-progress", ProgressBar).update(total=max(total, 1), progress=done)
        self.query_one("#scan-status", Static).update(text)

    @on(Button.Pressed, "#scan")
    def _scan(self) -> None:
        request = self.request()
        if isinstance(request, str):
            self.notify(request, severity="warning")
            return
        self.post_message(self.Requested(request))

    @on(Button.Pressed, "#abort")
    def _abort(self) -> None:
        self.post_message(self.Requested(None))
