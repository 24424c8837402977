"""Live values of one motor (position, speed, load, temperature, voltage) with a sparkline."""
# ruff: noqa: TID253  (the TUI package is only imported by `poppy tui`, lazily)

from __future__ import annotations

from collections import deque

from textual.app import ComposeResult
from textual.containers import Vertical
from textual.widgets import Sparkline, Static

from poppy_cli.tui.busio import LiveValues

HISTORY = 60


class LivePanel(Vertical):
    """Present values refreshed as samples arrive, the position plotted over the last samples."""

    def __init__(self, *, id: str | None = None) -> None:
        super().__init__(id=id)
        self.history: deque[float] = deque(maxlen=HISTORY)
        self.samples = 0

    def compose(self) -> ComposeResult:
        yield Static("no motor: pick one in the Bus tab", id="live-title", classes="title")
        yield Static("", id="live-values")
        yield Sparkline([], id="live-plot")
        yield Static("", id="live-goal")

    def set_title(self, text: str) -> None:
        """Name the motor shown."""
        self.query_one("#live-title", Static).update(text)

    def reset(self) -> None:
        """Forget the plotted history (another motor)."""
        self.history.clear()
        self.query_one("#live-plot", Sparkline).data = []
        self.query_one("#live-values", Static).update("")

    def show(self, values: LiveValues) -> None:
        """Show one sample."""
        self.samples += 1
        self.history.append(values.position_deg)
        self.query_one("#live-values", Static).update(
            f"position {values.position_deg:8.1f} °\n"
            f"speed    {values.speed_dps:8.1f} °/s\n"
            f"load     {values.load_percent:8.1f} %\n"
            f"temp     {values.temperature_c:8.0f} °C\n"
            f"voltage  {values.voltage_v:8.1f} V"
        )
        self.query_one("#live-plot", Sparkline).data = list(self.history)

    def show_goal(self, goal_deg: float | None, limits: tuple[float, float], state: str) -> None:
        """Show the dial's goal, the angle limits and torque/LED state."""
        goal = "?" if goal_deg is None else f"{goal_deg:.1f}°"
        self.query_one("#live-goal", Static).update(
            f"goal {goal}  ←/→ ±1° ⇧ ±10°\nlimits {limits[0]:.0f}°..{limits[1]:.0f}°\n{state}"
        )
