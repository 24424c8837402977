"""Robot tab, Primitives view: the attached primitives, their state, start/stop/pause/resume."""
# ruff: noqa: TID253  (the TUI package is only imported by `poppy tui`, lazily)

from __future__ import annotations

from typing import TYPE_CHECKING, ClassVar

from textual import on, work
from textual.app import ComposeResult
from textual.binding import Binding, BindingType
from textual.containers import Horizontal, Vertical
from textual.widgets import Button, DataTable

from poppy_cli.tui.messages import BusFailed
from poppy_cli.tui.text import set_cell
from poppy_core.errors import PoppyError

if TYPE_CHECKING:
    from poppy_core.motion import Primitive, PrimitiveFailure
    from poppy_core.robot import Robot

PRIMITIVE_COLUMNS = ("primitive", "state", "error")
ERROR_WIDTH = 48
"""Characters of the error one-liner shown in the table (the notification has it all)."""


def robot_primitives(robot: Robot) -> dict[str, Primitive]:
    """Attach the built-ins (as `poppy primitive` does) and give name -> attached primitive."""
    from poppy_core.motion import attach_builtins, attached_primitives

    attach_builtins(robot)
    return attached_primitives(robot)


def short_error(error: PrimitiveFailure | None) -> str:
    """The failure as one line, cut to ``ERROR_WIDTH`` characters ("" without failure)."""
    if error is None:
        return ""
    text = error.one_line
    return text if len(text) <= ERROR_WIDTH else text[: ERROR_WIDTH - 1] + "…"


class PrimitivesPanel(Vertical):
    """The robot's primitives; each runs in its own thread, the table only polls their state."""

    BINDINGS: ClassVar[list[BindingType]] = [
        Binding("s", "start", "Start"),
        Binding("x", "stop", "Stop"),
        Binding("p", "pause", "Pause"),
    ]

    def __init__(self, *, id: str | None = None) -> None:
        super().__init__(id=id)
        self.robot: Robot | None = None
        self.primitives: dict[str, Primitive] = {}
        self._reported: dict[str, PrimitiveFailure] = {}

    def compose(self) -> ComposeResult:
        yield DataTable[str](id="primitive-table", cursor_type="row", zebra_stripes=True)
        with Horizontal(classes="row"):
            yield Button("Start", id="primitive-start", variant="primary")
            yield Button("Stop", id="primitive-stop")
            yield Button("Pause/resume", id="primitive-pause")

    def on_mount(self) -> None:
        table = self.query_one("#primitive-table", DataTable)
        for column in PRIMITIVE_COLUMNS:
            table.add_column(column, key=column)

    def release(self) -> None:
        """Forget the robot (it is being closed; closing stops its primitives). No widget use."""
        self.robot = None
        self.primitives = {}

    def set_robot(self, robot: Robot) -> None:
        """Show the primitives of ``robot`` (the built-ins are attached to it)."""
        self.robot = robot
        self.primitives = robot_primitives(robot)
        self._reported = {}
        table = self.query_one("#primitive-table", DataTable)
        table.clear()
        for name, primitive in self.primitives.items():
            table.add_row(name, primitive.state, short_error(primitive.error), key=name)

    def refresh_states(self) -> None:
        """Show each primitive's state; a new failure is notified once."""
        if self.robot is None or self.robot.closed:
            return
        table = self.query_one("#primitive-table", DataTable)
        for name, primitive in self.primitives.items():
            error = primitive.error
            set_cell(table, name, "state", primitive.state)
            set_cell(table, name, "error", short_error(error))
            if error is not None and self._reported.get(name) is not error:
                self._reported[name] = error
                self.notify(
                    f"primitive {name} failed: {error.one_line}", severity="error", timeout=8
                )

    @property
    def selected(self) -> str | None:
        """The name of the primitive under the cursor."""
        table = self.query_one("#primitive-table", DataTable)
        if table.row_count == 0:
            return None
        return str(table.coordinate_to_cell_key(table.cursor_coordinate).row_key.value)

    def _chosen(self) -> Primitive | None:
        name = self.selected
        if self.robot is None or name is None:
            self.notify("open a robot first", severity="warning")
            return None
        return self.primitives[name]

    def action_start(self) -> None:
        """Start (or restart) the primitive under the cursor, the motors stiffened first."""
        primitive = self._chosen()
        if primitive is not None and self.selected is not None:
            self._lifecycle(self.selected, primitive, True)

    def action_stop(self) -> None:
        """Stop the primitive under the cursor."""
        primitive = self._chosen()
        if primitive is not None and self.selected is not None:
            self._lifecycle(self.selected, primitive, False)

    def action_pause(self) -> None:
        """Pause the running primitive under the cursor, or resume it (neither blocks)."""
        primitive = self._chosen()
        if primitive is None:
            return
        if primitive.state == "paused":
            primitive.resume()
        elif primitive.state == "running":
            primitive.pause()
        else:
            self.notify(f"{self.selected} is {primitive.state}: start it first", severity="warning")
        self.refresh_states()

    @work(thread=True, group="primitives", exit_on_error=False)
    def _lifecycle(self, name: str, primitive: Primitive, start: bool) -> None:
        """Start or stop in a thread: both may join the primitive's thread."""
        try:
            if start:
                robot = self.robot
                if robot is not None:
                    robot.compliant = False  # primitives request goals: the torque must be on
                primitive.start()
            else:
                primitive.halt()  # a failure shows in the table (state failed)
        except (PoppyError, RuntimeError) as exc:
            verb = "start" if start else "stop"
            self.post_message(BusFailed(f"cannot {verb} primitive {name}: {exc}"))

    @on(DataTable.RowSelected, "#primitive-table")
    def _row_selected(self) -> None:
        self.action_start()

    @on(Button.Pressed, "#primitive-start")
    def _start_pressed(self) -> None:
        self.action_start()

    @on(Button.Pressed, "#primitive-stop")
    def _stop_pressed(self) -> None:
        self.action_stop()

    @on(Button.Pressed, "#primitive-pause")
    def _pause_pressed(self) -> None:
        self.action_pause()
