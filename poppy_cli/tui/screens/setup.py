"""Setup screen: a kit's motors set up one at a time, the flow of `poppy setup motors`."""
# ruff: noqa: TID253  (the TUI package is only imported by `poppy tui`, lazily)
# The steps are poppy_core.robot.guided_setup.GuidedSetup's, as the CLI runs them: the screen
# shows the prompt ("plug only m3 (XL-320) on the bus and press Enter"), runs the step in a
# thread worker when Enter is pressed, and shows what it did, or why it failed (Enter tries the
# same motor again).

from __future__ import annotations

from typing import ClassVar

from rich.text import Text
from textual import work
from textual.app import ComposeResult
from textual.binding import Binding, BindingType
from textual.containers import Vertical
from textual.screen import Screen
from textual.widgets import Footer, Header, Log, Static

from poppy_core.errors import PoppyError
from poppy_core.robot.guided_setup import GuidedSetup, StepOutcome


class SetupScreen(Screen[None]):
    """Walk a profile's motors: Enter sets the motor prompted up, s skips it, Escape leaves."""

    BINDINGS: ClassVar[list[BindingType]] = [
        Binding("enter", "step", "Set up"),
        Binding("s", "skip", "Skip"),
        Binding("escape", "leave", "Back"),
    ]

    def __init__(self, flow: GuidedSetup, profile: str) -> None:
        super().__init__()
        self.flow = flow
        self.profile = profile
        self.index = 0
        self.busy = False
        self.outcomes: list[StepOutcome] = []
        self.errors: list[str] = []

    def compose(self) -> ComposeResult:
        yield Header()
        with Vertical(id="setup"):
            yield Static(
                Text(
                    f"Set up {self.profile}'s {len(self.flow.targets)} motors on "
                    f"{self.flow.port}, one at a time"
                ),
                id="setup-title",
            )
            yield Static("", id="setup-prompt")
            yield Log(id="setup-log", highlight=False)
        yield Footer(compact=True)

    def on_mount(self) -> None:
        self._show_prompt()

    @property
    def done(self) -> bool:
        return self.index >= len(self.flow.targets)

    @property
    def prompt(self) -> str:
        """What the screen asks now."""
        if self.done:
            return f"all motors done: check the robot with `poppy doctor --profile {self.profile}`"
        return self.flow.targets[self.index].prompt

    def _show_prompt(self) -> None:
        self.query_one("#setup-prompt", Static).update(Text(self.prompt))

    def _log(self, line: str) -> None:
        self.query_one("#setup-log", Log).write_line(line)

    def action_step(self) -> None:
        """Set the motor prompted up (in a thread: the bus work must not stall the screen)."""
        if self.busy or self.done:
            return
        self.busy = True
        self._run(self.index)

    def action_skip(self) -> None:
        """Go on to the next motor without touching this one."""
        if self.busy or self.done:
            return
        self._log(f"{self.flow.targets[self.index].name}: skipped")
        self.index += 1
        self._show_prompt()

    def action_leave(self) -> None:
        """Back to the main screen (a step under way finishes first)."""
        if not self.busy:
            self.app.pop_screen()

    @work(thread=True, exclusive=True, group="setup")
    def _run(self, index: int) -> None:
        target = self.flow.targets[index]

        def say(line: str) -> None:
            self.app.call_from_thread(self._log, f"· {line}")

        try:
            outcome = self.flow.set_up(target, say)
        except PoppyError as exc:
            self.app.call_from_thread(self._failed, str(exc))
            return
        self.app.call_from_thread(self._succeeded, outcome)

    def _succeeded(self, outcome: StepOutcome) -> None:
        self.outcomes.append(outcome)
        self._log(f"✓ {outcome.summary()}")
        self.index += 1
        self.busy = False
        self._show_prompt()

    def _failed(self, message: str) -> None:
        self.errors.append(message)
        self._log(f"✗ {message} (Enter: try again, s: skip)")
        self.busy = False
