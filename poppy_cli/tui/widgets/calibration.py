"""The robot tab's calibration: a ``CalibrationSession`` guided in a modal screen, then saved."""
# ruff: noqa: TID253  (the TUI package is only imported by `poppy tui`, lazily)

from __future__ import annotations

import threading
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any, ClassVar

from rich.text import Text
from textual import on, work
from textual.app import ComposeResult
from textual.binding import Binding, BindingType
from textual.containers import Horizontal, Vertical
from textual.screen import ModalScreen
from textual.widgets import Button, DataTable, Static

from poppy_cli.tui.text import fixed, set_cell, short
from poppy_core.errors import CalibrationCancelled, PoppyError

if TYPE_CHECKING:
    from poppy_core.robot import Robot
    from poppy_core.robot.calibration import Calibration, ReferencePosture
    from poppy_core.robot.calibration_session import CalibrationEvent, RangeWatch

REFRESH_S = 0.1
RANGE_COLUMNS = ("joint", "now °", "low °", "high °", "span °")
CHANGE_COLUMNS = ("joint", "offset °", "angle limit °")


class ScreenAnswers:
    """The session's questions (asked from its worker thread) shown on the screen; each call
    waits for a button, or for the screen to be cancelled."""

    def __init__(self, screen: CalibrationScreen) -> None:
        self.screen = screen

    def _ask(self, show: Callable[[], None]) -> bool:
        answered = threading.Event()
        self.screen.answer = None
        self.screen.answered = answered
        self.screen.app.call_from_thread(show)
        while not answered.wait(0.1):
            if self.screen.cancelled.is_set():
                return False
        return bool(self.screen.answer)

    def posture(self, posture: ReferencePosture, motors: Sequence[str]) -> bool:
        """Show the reference posture; Continue once the robot is in it."""
        text = posture.description
        if posture.image is not None:
            text += f"\n\npicture: {posture.image}"
        if posture.positions:
            angles = ", ".join(f"{m} {short(v)}°" for m, v in posture.positions.items())
            text += f"\n\nangles: {angles}"
        text += f"\n\n{', '.join(motors)} are compliant: put the robot in this posture."
        return self._ask(lambda: self.screen.show_step("Reference posture", text))

    def move(self, motors: Sequence[str], watch: RangeWatch) -> bool:
        """Show the joints' ranges live; Continue when they went through their range."""
        which = motors[0] if len(motors) == 1 else "each joint"
        text = (
            f"Move {which} slowly from one end of its range to the other, back to the "
            "posture, then Continue."
        )
        return self._ask(lambda: self.screen.show_step("Ranges", text, watch))

    def confirm(self, question: str) -> bool:
        """A yes/no question (Continue: yes)."""
        return self._ask(lambda: self.screen.show_step("Question", question, yes_no=True))


class CalibrationScreen(ModalScreen[str | None]):
    """Calibrate ``robot``'s joints, review the changes, write the user profile ``name``.

    Dismissed with the path written, or None when cancelled or discarded (nothing written).
    """

    BINDINGS: ClassVar[list[BindingType]] = [Binding("escape", "cancel", "Cancel")]
    DEFAULT_CSS = """
    CalibrationScreen { align: center middle; }
    #calibration { width: 90%; height: auto; max-height: 90%; border: thick $primary;
                   background: $surface; padding: 1 2; }
    #calibration-ranges { height: auto; max-height: 14; }
    #calibration-buttons { height: auto; margin-top: 1; }
    """

    def __init__(self, robot: Robot, name: str, motors: Sequence[str] | None = None) -> None:
        super().__init__()
        self.robot = robot
        self.profile_name = name
        self.motors = list(motors) if motors is not None else None
        self.cancelled = threading.Event()
        self.answered: threading.Event | None = None
        self.answer: bool | None = None
        self.calibration: Calibration | None = None
        self._watch: RangeWatch | None = None
        self._saving = False
        self._yes_no = False

    def compose(self) -> ComposeResult:
        with Vertical(id="calibration"):
            yield Static(
                Text(f"Calibrate → user profile {self.profile_name!r}", style="bold"),
                id="calibration-title",
            )
            yield Static(Text("starting…"), id="calibration-text")
            yield DataTable[str](id="calibration-ranges", cursor_type="none")
            yield Static(Text(""), id="calibration-event")
            with Horizontal(id="calibration-buttons"):
                yield Button(
                    "Continue", id="calibration-continue", variant="primary", disabled=True
                )
                yield Button("Cancel", id="calibration-cancel", variant="error")

    def on_mount(self) -> None:
        self.set_interval(REFRESH_S, self._refresh_ranges)
        self._run()

    def on_unmount(self) -> None:
        self.cancelled.set()  # a session still asking (the app is quitting) ends, writing nothing
        self._reply(False)

    # -- the session, in a thread ---------------------------------------------------------------

    @work(thread=True, exclusive=True, group="calibration")
    def _run(self) -> None:
        from poppy_core.robot import CalibrationSession

        try:
            session = CalibrationSession(
                self.robot, ScreenAnswers(self), self.motors, on_event=self._event_from_thread
            )
            calibration = session.run()
        except CalibrationCancelled:
            self.app.call_from_thread(self.dismiss, None)
            return
        except PoppyError as exc:
            self.app.call_from_thread(self._failed, str(exc))
            return
        self.app.call_from_thread(self._review, calibration)

    def _event_from_thread(self, event: CalibrationEvent) -> None:
        self.app.call_from_thread(self._show_event, event)

    def _show_event(self, event: CalibrationEvent) -> None:
        step = f" ({event.index}/{event.total})" if event.total else ""
        self.query_one("#calibration-event", Static).update(Text(f"{event.message}{step}"))

    # -- what the screen shows ------------------------------------------------------------------

    def show_step(
        self, title: str, text: str, watch: RangeWatch | None = None, *, yes_no: bool = False
    ) -> None:
        """Show one question of the session, with its ranges when ``watch`` is given."""
        self.query_one("#calibration-title", Static).update(Text(title, style="bold"))
        self.query_one("#calibration-text", Static).update(Text(text))
        self._watch = watch
        self._yes_no = yes_no
        table = self.query_one("#calibration-ranges", DataTable)
        table.clear(columns=True)
        if watch is not None:
            for column in RANGE_COLUMNS:
                table.add_column(column, key=column)
            for reading in watch.readings():
                table.add_row(*self._range_cells(reading), key=reading.motor)
        go = self.query_one("#calibration-continue", Button)
        go.label = "Yes" if yes_no else "Continue"
        go.disabled = False
        self.query_one("#calibration-cancel", Button).label = "No" if yes_no else "Cancel"
        go.focus()

    @staticmethod
    def _range_cells(reading: Any) -> tuple[str, ...]:
        return (
            reading.motor,
            fixed(reading.current),
            fixed(reading.low),
            fixed(reading.high),
            fixed(reading.span),
        )

    def _refresh_ranges(self) -> None:
        if self._watch is None:
            return
        table = self.query_one("#calibration-ranges", DataTable)
        for reading in self._watch.readings():
            for column, text in zip(RANGE_COLUMNS, self._range_cells(reading), strict=True):
                set_cell(table, reading.motor, column, text)

    def _review(self, calibration: Calibration) -> None:
        from poppy_core.robot.profile_store import user_profile_path

        assert self.robot.config is not None
        self.calibration = calibration
        self._watch = None
        self._saving = True
        changes = calibration.changes(self.robot.config)
        table = self.query_one("#calibration-ranges", DataTable)
        table.clear(columns=True)
        for column in CHANGE_COLUMNS:
            table.add_column(column, key=column)
        for motor, change in changes.items():
            old_offset, new_offset = change["offset"]
            old_limit, new_limit = change["angle_limit"]
            table.add_row(
                motor,
                f"{short(old_offset)} → {short(new_offset)}",
                f"{short(old_limit[0])}…{short(old_limit[1])} → "
                f"{short(new_limit[0])}…{short(new_limit[1])}",
                key=motor,
            )
        self.query_one("#calibration-title", Static).update(Text("Review", style="bold"))
        path = user_profile_path(self.profile_name)
        self.query_one("#calibration-text", Static).update(
            Text(f"Write these to {path}? (the previous file, if any, is kept as .bak)")
        )
        go = self.query_one("#calibration-continue", Button)
        go.label, go.disabled = "Save", False
        self.query_one("#calibration-cancel", Button).label = "Discard"
        go.focus()

    def _failed(self, message: str) -> None:
        self.notify(f"calibration: {message}", severity="error")
        self.dismiss(None)

    # -- buttons --------------------------------------------------------------------------------

    @on(Button.Pressed, "#calibration-continue")
    def _continue(self) -> None:
        if self._saving:
            self._save()
            return
        self.query_one("#calibration-continue", Button).disabled = True
        self._reply(True)

    @on(Button.Pressed, "#calibration-cancel")
    def _cancel_pressed(self) -> None:
        if self._yes_no and not self._saving:
            self._yes_no = False
            self._reply(False)  # "No" to the session's question
            return
        self.action_cancel()

    def action_cancel(self) -> None:
        """Stop the session, or discard its result: nothing is written."""
        if self._saving:
            self.notify("calibration discarded: nothing was written")
            self.dismiss(None)
            return
        self.cancelled.set()
        self._reply(False)

    def _reply(self, answer: bool) -> None:
        self.answer = answer
        if self.answered is not None:
            self.answered.set()

    def _save(self) -> None:
        from poppy_core.robot.profile_store import save_calibration

        assert self.calibration is not None and self.robot.config is not None
        try:
            saved = save_calibration(
                self.robot.config, self.calibration, self.profile_name, by="poppy tui"
            )
        except PoppyError as exc:
            self.notify(str(exc), severity="error")
            return
        self.notify(f"wrote {saved.path}; --profile {self.profile_name} now uses it")
        self.dismiss(str(saved.path))
