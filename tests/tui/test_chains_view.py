"""Pilot tests of the Robot tab's Chains view: tip positions and x/y/z jogs on a virtual Ergo Jr."""

from __future__ import annotations

import numpy as np
from textual.widgets import DataTable, Input  # noqa: TID253  (a TUI test)

from poppy_cli.tui.app import PoppyApp, make_app
from poppy_cli.tui.widgets.robot_panel import RobotPanel
from tests.helpers.tui import no_ports, run_async, wait_for

SIZE = (80, 24)


def sim_app() -> PoppyApp:
    return make_app(port_lister=no_ports, live_period_s=0)


@run_async
async def test_chains_view_shows_the_tip_and_jogs_it() -> None:
    app = sim_app()
    async with app.run_test(size=SIZE) as pilot:
        await pilot.press("f3")
        panel = app.main.query_one(RobotPanel)
        panel.open("ergo-jr", True)
        await wait_for(pilot, lambda: panel.robot is not None, what="robot opened")
        robot = panel.robot
        assert robot is not None
        await pilot.press("4")
        table = panel.query_one("#chain-table", DataTable)
        assert table.has_focus and table.row_count == 1
        chain = robot.chain
        await wait_for(
            pilot,
            lambda: abs(float(table.get_cell("chain", "z mm")) - 1000 * chain.position[2]) < 1.0,
            what="tip shown",
        )
        panel.query_one("#jog-step", Input).value = "20"
        start = chain.position.copy()
        await pilot.press("Z")  # 20 mm down
        await wait_for(
            pilot, lambda: abs(chain.position[2] - (start[2] - 0.02)) < 0.003, what="jogged down"
        )
        assert np.linalg.norm(chain.position[:2] - start[:2]) < 0.003
        await pilot.press("x", "x")  # twice 20 mm along x: they add up
        goal = start + np.array([0.04, 0.0, -0.02])
        await wait_for(pilot, lambda: np.linalg.norm(chain.position - goal) < 0.003, what="x")
        await wait_for(
            pilot,
            lambda: abs(float(table.get_cell("chain", "z mm")) - 1000 * chain.position[2]) < 1.0,
            what="table follows",
        )


@run_async
async def test_a_jog_out_of_reach_is_a_notification() -> None:
    app = sim_app()
    async with app.run_test(size=SIZE) as pilot:
        await pilot.press("f3")
        panel = app.main.query_one(RobotPanel)
        panel.open("ergo-jr", True)
        await wait_for(pilot, lambda: panel.robot is not None, what="robot opened")
        await pilot.press("4")
        panel.query_one("#jog-step", Input).value = "500"
        await pilot.press("z")
        await wait_for(
            pilot,
            lambda: any("cannot reach" in n.message for n in app._notifications),
            what="error note",
        )
