"""Motor panel: control table, inline edits (one or several motors), live view, dial, toggles."""
# ruff: noqa: TID253  (the TUI package is only imported by `poppy tui`, lazily)

from __future__ import annotations

import time
from typing import ClassVar

from textual import on, work
from textual.app import ComposeResult
from textual.binding import Binding, BindingType
from textual.containers import Horizontal
from textual.widgets import DataTable
from textual.worker import get_current_worker

from poppy_cli.tui.busio import BusPool, MotorRef, SIValue, read_live, read_table
from poppy_cli.tui.messages import (
    BusFailed,
    LiveSampled,
    MotorMoved,
    TableRead,
    ValueWritten,
)
from poppy_cli.tui.ops import restart, toggled, write_value
from poppy_cli.tui.screens.modals import Confirm, EditValue
from poppy_cli.tui.widgets.control_table import ControlTableView, format_value
from poppy_cli.tui.widgets.live import LivePanel
from poppy_core.errors import PoppyError, SetupError
from poppy_core.models import ServoModel

BUSY_WAIT_S = 0.2


def refusal_hint(register: str, memory: str, text: str) -> str:
    """Say why a motor refused a write, with the fix when it is the usual EEPROM lock."""
    if memory == "EEPROM" and "access" in text.lower():
        return f"{text}: EEPROM registers are locked while the torque is on (press t first)"
    return text


class MotorPanel(Horizontal):
    """The motor chosen in the tree: its table on the left, live values on the right."""

    BINDINGS: ClassVar[list[BindingType]] = [
        Binding("t", "torque", "Torque"),
        Binding("l", "led", "LED"),
        Binding("r", "reread", "Re-read"),
        Binding("b", "restart('reboot')", "Reboot"),
        Binding("f", "restart('reset')", "Reset"),
    ]

    def __init__(self, pool: BusPool, live_period_s: float, *, id: str | None = None) -> None:
        super().__init__(id=id)
        self.pool = pool
        self.live_period_s = live_period_s
        self.motor: MotorRef | None = None
        self.others: list[MotorRef] = []
        self.goal_deg: float | None = None

    def compose(self) -> ComposeResult:
        yield ControlTableView(id="control-table")
        yield LivePanel(id="live")

    @property
    def targets(self) -> list[MotorRef]:
        """The motors an edit applies to: the one shown and those marked in the tree."""
        if self.motor is None:
            return []
        return [self.motor, *(m for m in self.others if m.key != self.motor.key)]

    @property
    def model(self) -> ServoModel | None:
        """The shown motor's model, None when unknown."""
        if self.motor is None or self.motor.model is None:
            return None
        return self.motor.servo_model()

    def open(self, motor: MotorRef, marked: list[MotorRef]) -> None:
        """Show ``motor`` (and apply edits to ``marked`` too)."""
        self.motor = motor
        self.others = [m for m in marked if m.key != motor.key]
        self.goal_deg = None
        live = self.query_one(LivePanel)
        live.reset()
        extra = f" (+{len(self.others)} marked)" if self.others else ""
        live.set_title(f"id {motor.id} {motor.model or '?'}{extra}")
        self.query_one(ControlTableView).show([])
        if motor.model is None:
            self.notify(f"motor {motor.id}: unknown model, no table", severity="warning")
            return
        self.load_table(motor)
        if self.live_period_s > 0:
            self.live_loop(motor)

    def value(self, name: str) -> SIValue | None:
        """The last value read of register ``name`` (aliases resolved)."""
        model = self.model
        if model is None or not model.has_register(name):
            return None
        row = self.query_one(ControlTableView).values.get(model.register(name).name)
        return None if row is None else row.value

    # -- workers (thread: every bus transaction blocks) ----------------------------------------

    @work(thread=True, exclusive=True, group="table", exit_on_error=False)
    def load_table(self, motor: MotorRef) -> None:
        """Read the whole control table."""
        try:
            with self.pool.bus(motor) as bus:
                rows = read_table(bus, motor.id, motor.servo_model())
        except PoppyError as exc:
            self.post_message(BusFailed(f"motor {motor.id}: cannot read its table: {exc}"))
            return
        self.post_message(TableRead(motor, rows))

    @work(thread=True, exclusive=True, group="live", exit_on_error=False)
    def live_loop(self, motor: MotorRef) -> None:
        """Sample the live registers every ``live_period_s`` until cancelled."""
        worker = get_current_worker()
        model = motor.servo_model()
        failing = False
        next_s = time.monotonic()
        while not worker.is_cancelled:
            try:
                with self.pool.bus(motor, timeout_s=BUSY_WAIT_S) as bus:
                    values = read_live(bus, motor.id, model)
            except SetupError:
                time.sleep(BUSY_WAIT_S)  # the port is busy (a scan): wait for it
                continue
            except PoppyError as exc:
                if not failing:
                    self.post_message(BusFailed(f"motor {motor.id}: live read failed: {exc}"))
                failing = True
                time.sleep(0.5)
                continue
            failing = False
            self.post_message(LiveSampled(motor, values))
            next_s = max(next_s + self.live_period_s, time.monotonic())
            time.sleep(max(0.0, next_s - time.monotonic()))

    @work(thread=True, group="write", exit_on_error=False)
    def write(self, motors: list[MotorRef], register: str, value: SIValue) -> None:
        """Write one value to several motors; refusals come back in the outcome."""
        self.post_message(ValueWritten(write_value(self.pool, motors, register, value)))

    @work(thread=True, exclusive=True, group="goal", exit_on_error=False)
    def write_goal(self, motor: MotorRef, goal_deg: float) -> None:
        """Send a goal position (the newest dial value wins)."""
        outcome = write_value(self.pool, [motor], "goal_position", goal_deg)
        for _, text in outcome.failed:
            self.post_message(BusFailed(f"motor {motor.id}: goal position refused: {text}"))

    @work(thread=True, group="write", exit_on_error=False)
    def run_restart(self, motor: MotorRef, action: str) -> None:
        """Reboot or factory-reset, then read the table again."""
        try:
            after = restart(self.pool, motor, action)
        except PoppyError as exc:
            self.post_message(BusFailed(f"motor {motor.id}: {action} failed: {exc}"))
            return
        if after != motor:
            self.post_message(MotorMoved(motor, after))
        self.app.call_from_thread(self.notify, f"motor {after.id}: {action} done")
        self.app.call_from_thread(self.open, after, self.others)

    # -- results (UI thread) -------------------------------------------------------------------

    @on(TableRead)
    def _table_read(self, message: TableRead) -> None:
        message.stop()
        if self.motor is None or message.motor.key != self.motor.key:
            return
        self.query_one(ControlTableView).show(message.rows)
        goal = self.value("goal_position")
        self.goal_deg = float(goal) if isinstance(goal, int | float) else None
        self._show_goal()

    @on(LiveSampled)
    def _live(self, message: LiveSampled) -> None:
        message.stop()
        if self.motor is None or message.motor.key != self.motor.key:
            return
        self.query_one(LivePanel).show(message.values)
        model = self.model
        if model is None:
            return
        # The table shows the present values of this sample too, not those of the last full read.
        table = self.query_one(ControlTableView)
        for name, value in message.values.registers().items():
            row = table.values.get(model.register(name).name) if model.has_register(name) else None
            if row is None:
                continue
            whole = isinstance(row.value, int) and not isinstance(row.value, bool)
            table.set_value(row.register.name, round(value) if whole else value)

    @on(ValueWritten)
    def _written(self, message: ValueWritten) -> None:
        message.stop()
        outcome = message.outcome
        model = self.model
        memory = model.register(outcome.register).memory if model is not None else ""
        for motor, text in outcome.failed:
            hint = refusal_hint(outcome.register, memory, text)
            self.notify(f"motor {motor.id} refused {outcome.register}: {hint}", severity="error")
        for old, new in outcome.renamed.items():
            self.post_message(MotorMoved(old, new))
            if self.motor is not None and old.key == self.motor.key:
                self.motor = new
            self.others = [new if m.key == old.key else m for m in self.others]
        if outcome.done:
            shown = format_value(outcome.value, "")
            ids = ", ".join(str(m.id) for m in outcome.done)
            self.notify(f"{outcome.register} = {shown} on motor {ids}")
        if self.motor is not None and any(m.key == self.motor.key for m in outcome.done):
            self.load_table(self.motor)

    def _show_goal(self) -> None:
        low, high = self._limits()
        torque = self.value("torque_enable")
        led = self.value("led")
        state = f"torque {format_value(torque, '')} (t)\nled    {format_value(led, '')} (l)"
        self.query_one(LivePanel).show_goal(self.goal_deg, (low, high), state)

    def _limits(self) -> tuple[float, float]:
        model = self.model
        span = 180.0 if model is None else model.position_range_deg / 2
        low, high = self.value("min_position_limit"), self.value("max_position_limit")
        low_f = float(low) if isinstance(low, int | float) and not isinstance(low, bool) else -span
        high_f = (
            float(high) if isinstance(high, int | float) and not isinstance(high, bool) else span
        )
        return (low_f, high_f) if low_f < high_f else (-span, span)

    # -- keys ----------------------------------------------------------------------------------

    @on(DataTable.RowSelected, "#control-table")
    def _edit(self, event: DataTable.RowSelected) -> None:
        event.stop()
        row = self.query_one(ControlTableView).current
        if row is None or self.motor is None:
            return
        if not row.register.writable:
            self.notify(f"{row.register.name} is read-only", severity="warning")
            return
        targets = self.targets
        current = "" if row.value is None else format_value(row.value, "")
        name = row.register.name

        def done(value: SIValue | None) -> None:
            if value is not None:
                self.write(targets, name, value)

        self.app.push_screen(EditValue(row.register, current, len(targets)), done)

    @on(ControlTableView.Dialled)
    def _dialled(self, message: ControlTableView.Dialled) -> None:
        message.stop()
        if self.motor is None or self.model is None:
            return
        if self.goal_deg is None:
            self.notify("goal position not read yet", severity="warning")
            return
        low, high = self._limits()
        self.goal_deg = min(high, max(low, self.goal_deg + message.delta_deg))
        self.query_one(ControlTableView).set_value(
            self.model.register("goal_position").name, self.goal_deg
        )
        self._show_goal()
        self.write_goal(self.motor, self.goal_deg)

    def _toggle(self, name: str) -> None:
        model = self.model
        if self.motor is None or model is None or not model.has_register(name):
            return
        register = model.register(name)
        value = toggled(self.value(name), register)
        self.query_one(ControlTableView).set_value(register.name, value)
        self._show_goal()
        self.write(self.targets, register.name, value)

    def action_torque(self) -> None:
        """Toggle the torque of the motor (and the marked ones)."""
        self._toggle("torque_enable")

    def action_led(self) -> None:
        """Toggle the LED of the motor (and the marked ones)."""
        self._toggle("led")

    def action_reread(self) -> None:
        """Read the control table again."""
        if self.motor is not None and self.model is not None:
            self.load_table(self.motor)

    def action_restart(self, action: str) -> None:
        """Reboot or factory-reset the motor after a confirmation."""
        motor = self.motor
        if motor is None:
            return
        what = "Reboot" if action == "reboot" else "Factory-reset (keeping ID and baud rate)"

        def answered(yes: bool | None) -> None:
            if yes:
                self.run_restart(motor, action)

        self.app.push_screen(Confirm(f"{what} motor {motor.id}?"), answered)
