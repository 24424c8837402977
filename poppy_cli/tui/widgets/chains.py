"""Robot tab, Chains view: where each chain's tip is, and jogging it in x, y, z."""
# ruff: noqa: TID253  (the TUI package is only imported by `poppy tui`, lazily)

from __future__ import annotations

import time
from typing import TYPE_CHECKING, ClassVar

from textual import on, work
from textual.app import ComposeResult
from textual.binding import Binding, BindingType
from textual.containers import Horizontal, Vertical
from textual.widgets import Button, DataTable, Input, Label

from poppy_cli.tui.text import fixed, set_cell
from poppy_core.errors import PoppyError

if TYPE_CHECKING:
    from poppy_core.motion.cartesian import RobotChain
    from poppy_core.robot import Robot

CHAIN_COLUMNS = ("chain", "x mm", "y mm", "z mm", "x axis")
JOG_S = 0.3
"""Duration of one jog move."""
JOG_MEMORY_S = 1.5
"""Jogs this close together add up from the last target (the tip lags behind)."""
AXES = {"x": 0, "y": 1, "z": 2}


def robot_chains(robot: Robot) -> dict[str, RobotChain]:
    """Name -> the chains attached to the robot."""
    from poppy_core.motion.chains import robot_chains as attached

    return attached(robot)


class ChainsPanel(Vertical):
    """The robot's chains: tip positions polled from the motors' caches; jogs solved in a thread."""

    BINDINGS: ClassVar[list[BindingType]] = [
        Binding("x", "jog('x', 1)", "x+"),
        Binding("X", "jog('x', -1)", "x-"),
        Binding("y", "jog('y', 1)", "y+"),
        Binding("Y", "jog('y', -1)", "y-"),
        Binding("z", "jog('z', 1)", "z+"),
        Binding("Z", "jog('z', -1)", "z-"),
    ]

    def __init__(self, *, id: str | None = None) -> None:
        super().__init__(id=id)
        self.robot: Robot | None = None
        self.chains: dict[str, RobotChain] = {}
        self._target: tuple[str, float, list[float]] | None = None  # chain, time, position

    def compose(self) -> ComposeResult:
        yield DataTable[str](id="chain-table", cursor_type="row", zebra_stripes=True)
        with Horizontal(classes="row"):
            yield Label("step mm", classes="label")
            yield Input("10", id="jog-step", type="number")
            for axis in AXES:
                yield Button(f"{axis}-", id=f"jog-{axis}-minus", classes="jog")
                yield Button(f"{axis}+", id=f"jog-{axis}-plus", classes="jog")
        yield Label("", id="chain-status")

    def on_mount(self) -> None:
        table = self.query_one("#chain-table", DataTable)
        for column in CHAIN_COLUMNS:
            table.add_column(column, key=column)

    def release(self) -> None:
        """Forget the robot (it is being closed). No widget use."""
        self.robot = None
        self.chains = {}
        self._target = None

    def set_robot(self, robot: Robot) -> None:
        """Show the chains of ``robot``."""
        self.robot = robot
        self.chains = robot_chains(robot)
        self._target = None
        table = self.query_one("#chain-table", DataTable)
        table.clear()
        for name in self.chains:
            table.add_row(*self._cells(name), key=name)
        status = self.query_one("#chain-status", Label)
        if self.chains:
            status.update("x/X y/Y z/Z jog the selected chain's tip by the step")
        else:
            status.update("no kinematic chain: its config has no kinematics section")

    def _cells(self, name: str) -> tuple[str, ...]:
        pose = self.chains[name].pose
        x, y, z = (1000.0 * float(v) for v in pose[:3, 3])
        axis = ", ".join(fixed(float(v), 2) for v in pose[:3, 0])
        return self.chains[name].label, fixed(x), fixed(y), fixed(z), axis

    def poll(self) -> None:
        """Show where the tips are now (forward kinematics of the cached positions; no I/O)."""
        if self.robot is None or self.robot.closed or not self.chains:
            return
        table = self.query_one("#chain-table", DataTable)
        for name in self.chains:
            for column, text in zip(CHAIN_COLUMNS, self._cells(name), strict=True):
                set_cell(table, name, column, text)

    def selected(self) -> str | None:
        """The chain under the cursor (the first one when the table has no cursor yet)."""
        table = self.query_one("#chain-table", DataTable)
        if not self.chains or table.row_count == 0:
            return None
        return str(table.coordinate_to_cell_key(table.cursor_coordinate).row_key.value)

    def action_jog(self, axis: str, sign: int) -> None:
        """Move the selected chain's tip by the step along ``axis``."""
        name = self.selected()
        if self.robot is None or name is None:
            self.notify("open a robot with a kinematic chain first", severity="warning")
            return
        try:
            step_m = float(self.query_one("#jog-step", Input).value or 10.0) / 1000.0
        except ValueError:
            self.notify("the step is a number of millimetres", severity="error")
            return
        now = time.monotonic()
        last = self._target
        if last is not None and last[0] == name and now - last[1] < JOG_MEMORY_S:
            start = list(last[2])
        else:
            start = [float(v) for v in self.chains[name].position]
        start[AXES[axis]] += sign * step_m
        self._target = (name, now, start)
        self.jog(name, start)

    @on(Button.Pressed, ".jog")
    def _jog_pressed(self, event: Button.Pressed) -> None:
        _, axis, direction = str(event.button.id).split("-")
        self.action_jog(axis, 1 if direction == "plus" else -1)

    @work(thread=True, exclusive=True, group="jog", exit_on_error=False)
    def jog(self, name: str, target: list[float]) -> None:
        """Solve and start the move in a thread (a solve takes about a millisecond)."""
        chain = self.chains.get(name)
        if chain is None:
            return
        try:
            for motor in chain.active_motors:
                motor.compliant = False
            chain.goto(target, duration=JOG_S, control="minjerk")
        except PoppyError as exc:
            self._target = None
            self.app.call_from_thread(self.notify, str(exc), severity="error")
