"""The Robot tab's Health view: each bus's link, loop rates and offline motors, live."""

from __future__ import annotations

from textual.widgets import DataTable  # noqa: TID253  (a TUI test)

from tests.helpers.tui import run_async, wait_for
from tests.tui.test_robot_tab import SIZE, hand, open_sim, sim_app


@run_async
async def test_health_view_shows_the_bus_and_offline_motors() -> None:
    app = sim_app()
    async with app.run_test(size=SIZE) as pilot:
        panel, robot = await open_sim(pilot, app)
        await pilot.press("5")
        table = panel.query_one("#health-table", DataTable)
        assert table.has_focus
        assert table.get_cell("my_dxl_controller", "link") == "connected"
        await wait_for(pilot, lambda: table.get_cell("my_dxl_controller", "present Hz") != "0")
        hand(robot, 2)  # the emulated motor exists
        (server,) = robot.emulators.values()
        server.bus.unplug(2)
        await wait_for(
            pilot, lambda: table.get_cell("my_dxl_controller", "offline") == "m2", what="m2 offline"
        )
        server.bus.plug(2)
        await wait_for(
            pilot, lambda: table.get_cell("my_dxl_controller", "offline") == "none", what="m2 back"
        )
