"""Live values of one motor (position, speed, load, temperature, voltage) with a sparkline
and its scale (the highest and lowest position plotted)."""
# ruff: noqa: TID253  (the TUI package is only imported by `poppy tui`, lazily)

from __future__ import annotations

from collections import deque

from textual.app import ComposeResult
from textual.containers import Vertical
from textual.widgets import Sparkline, Static

from poppy_cli.tui.busio import LiveValues
from poppy_cli.tui.text import fixed

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
        yield Static("", id="live-max", classes="scale")
        yield Sparkline([], id="live-plot")
        yield Static("", id="live-min", classes="scale")
        yield Static("", id="live-goal")

    def set_title(self, text: str) -> None:
        """Name the motor shown."""
        self.query_one("#live-title", Static).update(text)

    def reset(self) -> None:
        """Forget the plotted history (another motor)."""
        self.history.clear()
        self.query_one("#live-plot", Sparkline).data = []
        for part in ("#live-values", "#live-max", "#live-min"):
            self.query_one(part, Static).update("")

    def show(self, values: LiveValues) -> None:
        """Show one sample."""
        self.samples += 1
        self.history.append(values.position_deg)
        self.query_one("#live-values", Static).update(
            f"position {fixed(values.position_deg, 1, 8)} °\n"
            f"speed    {fixed(values.speed_dps, 1, 8)} °/s\n"
            f"load     {fixed(values.load_percent, 1, 8)} %\n"
            f"temp     {fixed(values.temperature_c, 0, 8)} °C\n"
            f"voltage  {fixed(values.voltage_v, 1, 8)} V"
        )
        self.query_one("#live-plot", Sparkline).data = list(self.history)
        # The sparkline spans the lowest to the highest value plotted: say which they are.
        high, low = max(self.history), min(self.history)
        self.query_one("#live-max", Static).update(f"max {fixed(high, 1, 7)} °")
        self.query_one("#live-min", Static).update(
            f"min {fixed(low, 1, 7)} °  last {len(self.history)}"
        )

    def show_goal(self, goal_deg: float | None, limits: tuple[float, float], state: str) -> None:
        """Show the dial's goal, the angle limits and torque/LED state."""
        goal = "?" if goal_deg is None else f"{fixed(goal_deg)}°"
        low, high = fixed(limits[0], 0), fixed(limits[1], 0)
        self.query_one("#live-goal", Static).update(
            f"goal {goal}\n←/→ ±1°  ⇧ ±10°\nlimits {low}°..{high}°\n{state}"
        )
