"""The TUI as a new user meets it (issue 25 item 7): one robot for every tab of a ``--sim``
session, live values in the control table, no negative zero, no cut cell, a scaled sparkline,
toggles marked by more than a colour, the keys in the footer, the motor tree one key away."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

from textual.widgets import Checkbox, DataTable  # noqa: TID253  (a TUI test)
from textual.widgets._tabbed_content import ContentTabs  # noqa: TID253  (a TUI test)

from poppy_cli.tui.app import PoppyApp, make_app
from poppy_cli.tui.busio import LiveValues
from poppy_cli.tui.messages import LiveSampled
from poppy_cli.tui.text import fixed, short
from poppy_cli.tui.widgets.control_table import ControlTableView, format_value
from poppy_cli.tui.widgets.live import LivePanel
from poppy_cli.tui.widgets.motor_tree import MotorTree
from poppy_cli.tui.widgets.robot_panel import RobotPanel
from poppy_core.emulator import Endpoint
from poppy_core.robot import Robot
from tests.helpers.tui import no_ports, run_async, wait_for
from tests.tui.test_pilot import open_motor
from tests.tui.test_robot_tab import hand, open_sim, sim_app

SIZE = (80, 24)
ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs" / "tui.md"
ROBOT_PANEL = ROOT / "poppy_cli" / "tui" / "widgets" / "robot_panel.py"
NEGATIVE_ZERO = re.compile(r"(?<![\d.])-0(\.0+)?(?![\d.])")


def screen_lines(app: PoppyApp) -> list[str]:
    """The screen as the terminal shows it, one string per line. Notifications are dismissed
    first (a toast covers the right of the lines it floats over; the next frame is without)."""
    app.clear_notifications()
    return [strip.text for strip in app.screen._compositor.render_strips()]


def line_with(app: PoppyApp, word: str) -> str:
    lines = [line for line in screen_lines(app) if word in line]
    assert lines, f"{word!r} is not on the screen:\n" + "\n".join(screen_lines(app))
    return lines[0]


def shown(app: PoppyApp, word: str) -> str:
    """The first screen line with ``word`` ("" when none: for waits)."""
    return next((line for line in screen_lines(app) if word in line), "")


async def see(pilot: Any, app: PoppyApp, word: str, pattern: str) -> None:
    """Wait until the screen line with ``word`` matches ``pattern`` (30 s: a loaded machine
    once took longer than the usual 15 s); a failure says what the line showed."""
    seen: list[str] = []

    def matches() -> bool:
        seen[:] = [shown(app, word)]
        return re.search(pattern, seen[0]) is not None

    try:
        await wait_for(pilot, matches, timeout_s=30, what=f"{pattern!r}")
    except AssertionError as exc:
        raise AssertionError(f"{exc}; the line was {seen[0]!r}") from None


def footer(app: PoppyApp) -> str:
    return screen_lines(app)[-1]


async def footer_shows(pilot: Any, app: PoppyApp, keys: tuple[str, ...]) -> None:
    """Wait for the footer (recomposed when the focus moves) to show every key."""
    await wait_for(pilot, lambda: all(k in footer(app) for k in keys), what=f"{keys} in footer")


def cells(table: DataTable[Any]) -> list[str]:
    return [str(cell) for row in range(table.row_count) for cell in table.get_row_at(row)]


def near(a: object, b: float, tolerance: float = 1.0) -> bool:
    return isinstance(a, int | float) and abs(float(a) - b) <= tolerance


async def sim_session(pilot: Any, app: PoppyApp) -> tuple[RobotPanel, Robot]:
    """Wait for ``poppy tui --sim``'s robot and the scan of the Bus tab."""
    screen = app.main
    panel = screen.query_one(RobotPanel)
    await wait_for(
        pilot,
        lambda: panel.robot is not None and screen.last_scan is not None,
        timeout_s=30.0,
        what="the robot and the scan",
    )
    assert panel.robot is not None
    return panel, panel.robot


def bus_session(server: Endpoint, live_period_s: float = 0) -> PoppyApp:
    """An app scanning ``server``'s three XL-320; the caller runs it."""
    return make_app(server.url, 1_000_000, 2, port_lister=no_ports, live_period_s=live_period_s)


@run_async
async def test_sim_session_is_one_robot_in_every_tab() -> None:
    app = make_app(sim=True, port_lister=no_ports, live_period_s=0.05)
    async with app.run_test(size=SIZE) as pilot:
        _, robot = await sim_session(pilot, app)
        screen = app.main
        tree = screen.query_one(MotorTree)
        assert {m.port for m in tree.motors} == {bus.port for bus in robot.buses.values()}
        assert sorted(m.id for m in tree.motors) == [1, 2, 3, 4, 5, 6]
        # A goto in the Robot tab is what the Motor tab shows.
        robot.motor("m3").compliant = False
        robot.goto_position({"m3": 30.0}, 0.3)
        emulated = hand(robot, 3)
        await wait_for(pilot, lambda: abs(abs(emulated.present_position_deg) - 30) < 1, what="m3")
        await open_motor(pilot, screen, 3)
        live = screen.query_one(LivePanel)
        await wait_for(
            pilot,
            lambda: bool(live.history) and near(live.history[-1], emulated.present_position_deg),
            what="the Motor tab's live view of the robot's motor 3",
        )


@run_async
async def test_motor_tab_shows_the_present_speed_of_a_dance() -> None:
    app = make_app(sim=True, port_lister=no_ports, live_period_s=0.05)
    async with app.run_test(size=SIZE) as pilot:
        panel, robot = await sim_session(pilot, app)
        await open_motor(pilot, app.main, 1)
        dance = panel.primitives.primitives["dance"]
        dance.set_property("intro_s", 0.2)
        robot.compliant = False
        dance.start()
        try:
            await wait_for(
                pilot,
                lambda: re.search(r"speed +-?[1-9]", shown(app, "speed ")) is not None,
                what="a present speed while dancing",
            )
        finally:
            dance.stop()


@run_async
async def test_control_table_shows_the_live_values(xl320_server: Endpoint) -> None:
    app = bus_session(xl320_server, live_period_s=0.05)
    async with app.run_test(size=SIZE) as pilot:
        screen = app.main
        await wait_for(pilot, lambda: screen.last_scan is not None, what="scan")
        await open_motor(pilot, screen, 2)
        table = screen.query_one(ControlTableView)
        xl320_server.bus.motor(2).move_by_hand(29.9)
        table.move_cursor(row=table.get_row_index("present_position"), animate=False)
        await wait_for(pilot, lambda: "29.9 °" in shown(app, "position "), what="live")
        await wait_for(
            pilot,
            lambda: " 29.9 " in shown(app, "present_position"),
            what="the table's present position after a move by hand",
        )


@run_async
async def test_control_table_columns_fit_80_columns(xl320_server: Endpoint) -> None:
    app = bus_session(xl320_server)
    async with app.run_test(size=SIZE) as pilot:
        screen = app.main
        await wait_for(pilot, lambda: screen.last_scan is not None, what="scan")
        await open_motor(pilot, screen, 1)
        # Memory and the read-only mark are shown whole (not "EEPRO", no mark cut off).
        await see(pilot, app, "model_number", r"model_number +350 +EEPROM +ro\b")
        await see(pilot, app, "torque_enable", r"torque_enable +off +RAM +│")


@run_async
async def test_live_plot_shows_its_scale(xl320_server: Endpoint) -> None:
    app = bus_session(xl320_server)
    async with app.run_test(size=SIZE) as pilot:
        screen = app.main
        await wait_for(pilot, lambda: screen.last_scan is not None, what="scan")
        panel = await open_motor(pilot, screen, 2)
        assert panel.motor is not None
        for position in (3.0, 5.0, 15.0, 10.0):
            panel.post_message(LiveSampled(panel.motor, LiveValues(position, 0, 0, 35, 7.4)))
        await wait_for(pilot, lambda: "10.0 °" in shown(app, "position "), what="samples")
        # The sparkline spans the lowest to the highest position plotted: both are written.
        await see(pilot, app, "max ", r"max +15\.0 °")
        await see(pilot, app, "min ", r"min +3\.0 °")


def test_numbers_never_show_a_negative_zero() -> None:
    assert fixed(-0.0) == "0.0" and fixed(-0.04) == "0.0" and fixed(-0.0, 0) == "0"
    assert fixed(-0.06) == "-0.1" and fixed(-0.4, 0) == "0" and fixed(-0.6, 0) == "-1"
    assert format_value(-0.0, "°") == "0.0 °"
    assert short(-0.0) == "0" and short(-2.5) == "-2.5" and short(30.0) == "30"


@run_async
async def test_no_negative_zero_on_the_robot_and_motor_tabs(xl320_server: Endpoint) -> None:
    app = bus_session(xl320_server)
    async with app.run_test(size=SIZE) as pilot:
        panel, _ = await open_sim(pilot, app)
        table = panel.query_one("#robot-table", DataTable)
        await wait_for(pilot, lambda: table.row_count == 6, what="robot table")
        await pilot.pause(0.3)
        values = cells(table)
        # Indirect motors at 0 read -0.0 (0 times -1): the table says 0.
        assert not [c for c in values if NEGATIVE_ZERO.fullmatch(c)], values
        await wait_for(pilot, lambda: app.main.last_scan is not None, what="scan")
        motor = await open_motor(pilot, app.main, 1)
        assert motor.motor is not None
        motor.post_message(LiveSampled(motor.motor, LiveValues(-0.0, -0.0, -0.04, 35, 7.4)))
        await see(pilot, app, "speed ", "°/s")
        await see(pilot, app, "load ", " %")
        await see(pilot, app, "position ", " °")
        for word in ("position ", "speed ", "load "):
            assert not NEGATIVE_ZERO.search(line_with(app, word)), line_with(app, word)


@run_async
async def test_a_primitive_state_is_never_cut() -> None:
    app = sim_app()
    async with app.run_test(size=SIZE) as pilot:
        panel, _ = await open_sim(pilot, app)
        await pilot.press("2")
        primitives = panel.query_one("#primitive-table", DataTable)
        dance = panel.primitives.primitives["dance"]
        dance.set_property("intro_s", 0.2)
        primitives.move_cursor(row=primitives.get_row_index("dance"))
        await pilot.press("s")
        await wait_for(pilot, lambda: dance.state == "running", what="dance runs")
        await pilot.press("x")
        await wait_for(pilot, lambda: primitives.get_cell("dance", "state") == "stopped")
        # The column was sized for "idle" when the table was filled: it widens, "stopp" is gone.
        await wait_for(pilot, lambda: "stopped" in shown(app, "dance"), what="stopped")


@run_async
async def test_footer_shows_enter_a_tab_and_q(xl320_server: Endpoint) -> None:
    app = bus_session(xl320_server)
    async with app.run_test(size=SIZE) as pilot:
        screen = app.main
        await wait_for(pilot, lambda: screen.last_scan is not None, what="scan")
        await footer_shows(pilot, app, ("⏎ Open", "a Mark all", "tab Next", "q Quit"))
        await open_motor(pilot, screen, 1)
        await footer_shows(pilot, app, ("⏎ Edit", "t Torque", "tab Next", "q Quit"))
        await pilot.press("f3")
        for view in ("1", "2", "3", "4", "5"):
            await pilot.press(view)
            await footer_shows(pilot, app, ("tab Next", "q Quit"))


@run_async
async def test_toggles_show_a_mark_not_only_a_colour(xl320_server: Endpoint) -> None:
    app = bus_session(xl320_server)
    async with app.run_test(size=SIZE) as pilot:
        screen = app.main
        await wait_for(pilot, lambda: screen.last_scan is not None, what="scan")
        await pilot.pause(0.1)
        await see(pilot, app, "1,000,000 bps", "▐X▌")  # ticked (--baud 1000000)
        await see(pilot, app, "  500,000 bps", "▐ ▌")  # not ticked
        await pilot.press("f3")
        await wait_for(pilot, lambda: "▐ ▌ sim" in shown(app, " sim "), what="sim unticked")
        screen.query_one("#robot-sim", Checkbox).value = True
        await wait_for(pilot, lambda: "▐X▌ sim" in shown(app, " sim "), what="sim ticked")


@run_async
async def test_the_motor_tree_is_one_key_away(xl320_server: Endpoint) -> None:
    app = bus_session(xl320_server)
    async with app.run_test(size=SIZE) as pilot:
        screen = app.main
        await wait_for(pilot, lambda: screen.last_scan is not None, what="scan")
        tree = screen.query_one(MotorTree)
        screen.query_one(ContentTabs).focus()
        await pilot.press("tab")  # from the tab bar
        assert tree.has_focus, app.focused
        await pilot.press("f3", "f1")  # from another tab
        assert tree.has_focus, app.focused


NUMBERS = {"three": 3, "four": 4, "five": 5, "six": 6, "seven": 7}


def test_docs_count_the_robot_views_they_list() -> None:
    text = DOCS.read_text(encoding="utf-8")
    said = re.search(r"(\w+) views \(keys ([\d, ]+)\)", text)
    assert said is not None
    listed = re.findall(r"^\* \*\*(\w+)\*\*:", text.split("## Robot tab")[1], flags=re.M)
    keys = said.group(2).replace(" ", "").split(",")
    assert NUMBERS[said.group(1).lower()] == len(listed) == len(keys), (said.group(0), listed)
    panel_views = re.findall(r'TabPane\("(\w+) (\d)"', ROBOT_PANEL.read_text(encoding="utf-8"))
    assert [name for name, _ in panel_views] == listed
