"""Robot tab: open a profile or config (or a virtual robot); motors, primitives, moves, chains."""
# ruff: noqa: TID253  (the TUI package is only imported by `poppy tui`, lazily)

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, ClassVar

from textual import on, work
from textual.app import ComposeResult
from textual.binding import Binding, BindingType
from textual.containers import Horizontal, Vertical
from textual.widgets import Button, Checkbox, DataTable, Input, Select, TabbedContent, TabPane

from poppy_cli.targets import parse_targets
from poppy_cli.tui.messages import BusFailed, RobotOpened
from poppy_cli.tui.text import fixed, set_cell, short
from poppy_cli.tui.widgets.chains import ChainsPanel
from poppy_cli.tui.widgets.moves import MovesPanel
from poppy_cli.tui.widgets.primitives import PrimitivesPanel
from poppy_cli.tui.widgets.toggles import MarkedCheckbox
from poppy_core.errors import PoppyError

if TYPE_CHECKING:
    from poppy_core.robot import Robot
    from poppy_core.robot.factory import SimMode

REFRESH_S = 0.1
COLUMNS = ("motor", "id", "pos °", "goal °", "speed", "load %", "temp", "compliant", "driven by")
HEALTH_COLUMNS = ("bus", "link", "present Hz", "goals Hz", "timeouts", "retries", "offline")


def open_robot(source: str, sim: SimMode) -> Robot:
    """Build a robot from a config file path or a profile name (blocking).

    It goes through ``poppy_core.from_config``: a Poppy creature gets its behaviours attached.
    """
    from poppy_core import from_config, from_profile

    if Path(source).is_file():
        return from_config(Path(source), sim, sensors=False)
    return from_profile(source, sim=sim, sensors=False)


class MotorsView(Vertical):
    """The Motors view: the live table, goto and group compliance (actions on the panel)."""

    BINDINGS: ClassVar[list[BindingType]] = [Binding("c", "toggle_compliant", "Compliant")]

    def action_toggle_compliant(self) -> None:
        """Toggle the compliance of the motor under the cursor."""
        self.query_ancestor(RobotPanel).toggle_compliant()


class RobotPanel(Vertical):
    """A whole robot: its motors from the caches (no bus I/O here), primitives and moves."""

    # The view tabs' labels show these keys (the footer has no room for them at 80 columns).
    BINDINGS: ClassVar[list[BindingType]] = [
        Binding("1", "view('robot-motors')", "Motors", show=False),
        Binding("2", "view('robot-primitives')", "Primitives", show=False),
        Binding("3", "view('robot-moves')", "Moves", show=False),
        Binding("4", "view('robot-chains')", "Chains", show=False),
        Binding("5", "view('robot-health')", "Health", show=False),
    ]

    def __init__(self, *, id: str | None = None) -> None:
        super().__init__(id=id)
        self.robot: Robot | None = None
        self.primitives = PrimitivesPanel(id="primitives")
        self.moves = MovesPanel(id="moves")
        self.chains = ChainsPanel(id="chains")

    def compose(self) -> ComposeResult:
        with Horizontal(classes="row"):
            yield Input(placeholder="profile (ergo-jr) or config file", id="robot-source")
            yield MarkedCheckbox("sim", id="robot-sim")
            yield Button("Open", id="robot-open")
        with TabbedContent(initial="robot-motors", id="robot-views"):
            with TabPane("Motors 1", id="robot-motors"), MotorsView():
                yield DataTable[str](id="robot-table", cursor_type="row", zebra_stripes=True)
                with Horizontal(classes="row"):
                    yield Input(placeholder="goto: m1=30 m2=-10", id="goto")
                    yield Input("1.0", id="goto-duration", type="number")
                    yield Button("Go", id="goto-go", variant="primary")
                with Horizontal(classes="row"):
                    yield Select[str]([], prompt="group", id="robot-group")
                    yield Button("Compliant", id="group-compliant")
                    yield Button("Stiff", id="group-stiff")
                    yield Button("Calibrate", id="robot-calibrate")
            with TabPane("Primitives 2", id="robot-primitives"):
                yield self.primitives
            with TabPane("Moves 3", id="robot-moves"):
                yield self.moves
            with TabPane("Chains 4", id="robot-chains"):
                yield self.chains
            with TabPane("Health 5", id="robot-health"):
                yield DataTable[str](id="health-table", cursor_type="row")

    def on_mount(self) -> None:
        table = self.query_one("#robot-table", DataTable)
        for column in COLUMNS:
            table.add_column(column, key=column)
        health = self.query_one("#health-table", DataTable)
        for column in HEALTH_COLUMNS:
            health.add_column(column, key=column)
        self.set_interval(REFRESH_S, self.refresh_table)

    def action_view(self, pane: str) -> None:
        """Show a view of the robot (Motors, Primitives, Moves) and focus its table."""
        self.query_one("#robot-views", TabbedContent).active = pane
        focus = {
            "robot-motors": "#robot-table",
            "robot-primitives": "#primitive-table",
            "robot-chains": "#chain-table",
            "robot-health": "#health-table",
        }
        self.query_one(focus.get(pane, "#moves-table")).focus()

    @work(thread=True, exclusive=True, group="robot", exit_on_error=False)
    def open(self, source: str, sim: SimMode) -> None:
        """Build the robot in a thread (it opens buses and starts the sync loops)."""
        try:
            robot = open_robot(source, sim)
        except PoppyError as exc:
            self.post_message(BusFailed(f"cannot open robot {source!r}: {exc}"))
            return
        self.post_message(RobotOpened(robot, f"{source}{' (sim)' if sim else ''}"))

    @on(RobotOpened)
    def _opened(self, message: RobotOpened) -> None:
        # Not stopped: the app scans the buses of the robot it opened at start.
        self.close_robot()
        self.robot = message.robot
        self.primitives.set_robot(message.robot)
        self.moves.set_robot(message.robot)
        self.chains.set_robot(message.robot)
        table = self.query_one("#robot-table", DataTable)
        table.clear()
        for motor in message.robot.motors:
            table.add_row(*self._cells(motor.name), key=motor.name)
        health = self.query_one("#health-table", DataTable)
        health.clear()
        for controller, cells in self._health_rows().items():
            health.add_row(*cells, key=controller)
        groups = [("all", "*"), *((name, name) for name in message.robot.motorgroups)]
        self.query_one("#robot-group", Select).set_options(groups)
        self.notify(f"robot {message.title}: {len(message.robot.motors)} motors")

    def _cells(self, name: str, owners: dict[str, str] | None = None) -> tuple[str, ...]:
        """A motor's row; ``owners``: who drives each motor's goal (``motion/leases.py``: a
        primitive running, a move playing), read once per refresh."""
        assert self.robot is not None
        motor = self.robot.motor(name)
        link = "" if motor.online else " offline"
        if owners is None:
            owners = self._owners()
        return (
            name,
            str(motor.id),
            fixed(motor.present_position),
            fixed(motor.goal_position),
            fixed(motor.present_speed, 0),
            fixed(motor.present_load, 0),
            fixed(motor.present_temperature, 0),
            ("yes" if motor.compliant else "no") + link,
            owners.get(name, ""),
        )

    def _owners(self) -> dict[str, str]:
        from poppy_core.motion.leases import motor_leases

        assert self.robot is not None
        return motor_leases(self.robot).labels()

    def _health_rows(self) -> dict[str, tuple[str, ...]]:
        """Controller -> its health cells (``Robot.health``: no I/O)."""
        assert self.robot is not None
        rows: dict[str, tuple[str, ...]] = {}
        for controller, bus in self.robot.health().items():
            link = "connected" if bus.connected else f"LOST {bus.down_s:.1f} s, reopening"
            rows[controller] = (
                bus.label,
                link,
                f"{bus.loop_hz.get('present', 0.0):.0f}",
                f"{bus.loop_hz.get('goals', 0.0):.0f}",
                str(bus.timeouts),
                str(bus.retries),
                ", ".join(bus.offline) or "none",
            )
        return rows

    def refresh_table(self) -> None:
        """Show the motors' cached values (the sync loops keep them fresh), the primitives'
        states and the recording or playback progress: polling only, no I/O."""
        if self.robot is None or self.robot.closed:
            return
        table = self.query_one("#robot-table", DataTable)
        owners = self._owners()
        for motor in self.robot.motors:
            for column, text in zip(COLUMNS, self._cells(motor.name, owners), strict=True):
                set_cell(table, motor.name, column, text)
        health = self.query_one("#health-table", DataTable)
        for controller, cells in self._health_rows().items():
            for column, text in zip(HEALTH_COLUMNS, cells, strict=True):
                set_cell(health, controller, column, text)
        self.primitives.refresh_states()
        self.moves.poll()
        self.chains.poll()

    def on_unmount(self) -> None:
        self.close_robot()

    def close_robot(self) -> None:
        """Close the robot (stops its recorder, player, primitives, loops and emulators)."""
        if self.robot is not None:
            self.moves.release()
            self.primitives.release()
            self.chains.release()
            self.robot.close()
            self.robot = None

    @on(Button.Pressed, "#robot-open")
    @on(Input.Submitted, "#robot-source")
    def _open_pressed(self) -> None:
        source = self.query_one("#robot-source", Input).value.strip()
        if not source:
            self.notify("type a profile name or a config file", severity="warning")
            return
        self.open(source, self.query_one("#robot-sim", Checkbox).value)

    @on(Button.Pressed, "#goto-go")
    @on(Input.Submitted, "#goto")
    @on(Input.Submitted, "#goto-duration")
    def _goto(self) -> None:
        if self.robot is None:
            self.notify("open a robot first", severity="warning")
            return
        try:
            words = self.query_one("#goto", Input).value.replace(",", " ").split()
            targets = parse_targets(words, [m.name for m in self.robot.motors])
            duration = float(self.query_one("#goto-duration", Input).value or 1.0)
            freed = [name for name in targets if self.robot.motor(name).compliant]
            for name in targets:
                self.robot.motor(name).compliant = False
            self.robot.goto_position(targets, max(duration, 0.0), wait=False)
        except (PoppyError, ValueError) as exc:
            self.notify(str(exc), severity="error")
            return
        if freed:  # a compliant motor does not move: the goto makes it stiff, and says so
            said = f"{', '.join(freed)} compliant: made stiff for the goto"
            self.notify(said, severity="warning")
        self.notify(f"goto {', '.join(f'{n}={short(v)}°' for n, v in targets.items())}")

    def toggle_compliant(self) -> None:
        """Toggle the compliance of the motor under the cursor."""
        table = self.query_one("#robot-table", DataTable)
        if self.robot is None or table.row_count == 0:
            return
        name = str(table.coordinate_to_cell_key(table.cursor_coordinate).row_key.value)
        motor = self.robot.motor(name)
        motor.compliant = not motor.compliant

    @on(Button.Pressed, "#group-compliant")
    @on(Button.Pressed, "#group-stiff")
    def _group(self, event: Button.Pressed) -> None:
        if self.robot is None:
            self.notify("open a robot first", severity="warning")
            return
        choice = self.query_one("#robot-group", Select).value
        motors = (
            self.robot.group(str(choice))
            if isinstance(choice, str) and choice != "*"
            else self.robot.motors
        )
        for motor in motors:
            motor.compliant = event.button.id == "group-compliant"

    @on(Button.Pressed, "#robot-calibrate")
    def _calibrate(self) -> None:
        """Calibrate the chosen group (or every joint) into the robot's user profile."""
        from poppy_cli.tui.widgets.calibration import CalibrationScreen

        robot = self.robot
        if robot is None:
            self.notify("open a robot first", severity="warning")
            return
        profile = robot.config.profile if robot.config is not None else None
        if profile is None:
            self.notify(
                "this robot has no profile name to calibrate into: use "
                "`poppy calibrate --name NAME`",
                severity="warning",
            )
            return
        choice = self.query_one("#robot-group", Select).value
        motors = (
            [m.name for m in robot.group(str(choice))]
            if isinstance(choice, str) and choice != "*"
            else None
        )
        self.app.push_screen(CalibrationScreen(robot, profile.name, motors))
