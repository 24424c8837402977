"""Snapshots of the main screens at 80x24 against an emulator on a fixed loopback port."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest
from textual.widgets import Input  # noqa: TID253  (a TUI test)

from poppy_cli.tui.app import PoppyApp, make_app
from poppy_cli.tui.busio import LiveValues
from poppy_cli.tui.messages import LiveSampled
from poppy_cli.tui.widgets.control_table import ControlTableView
from poppy_cli.tui.widgets.motor_panel import MotorPanel
from poppy_cli.tui.widgets.motor_tree import MotorTree
from poppy_cli.tui.widgets.robot_panel import RobotPanel
from poppy_core.bus import PortInfo
from poppy_core.emulator import EmulatorServer, build_bus_from_spec, serve_tcp
from poppy_core.errors import PortError
from tests.helpers.tui import wait_for

# Fixed, as the scan screen shows it; below Linux's ephemeral range (32768-60999), so that no
# connection of a parallel test can hold it by chance.
TCP_PORT = 29311
URL = f"socket://127.0.0.1:{TCP_PORT}"
SIZE = (80, 24)


def fixed_ports() -> list[PortInfo]:
    return [
        PortInfo(
            "/dev/ttyUSB0",
            "USB2AX",
            0x16D0,
            0x06A7,
            adapter="USB2AX",
            latency_timer_ms=16,
            advice=["latency timer is 16 ms (slow bus): echo 1 | sudo tee ..."],
        )
    ]


@pytest.fixture
def tcp_server() -> Iterator[EmulatorServer]:
    bus = build_bus_from_spec("XL-320:1-3", protocol=2, auto_step=False)
    try:
        server = serve_tcp(bus, "127.0.0.1", TCP_PORT)
    except PortError:
        pytest.skip(f"loopback port {TCP_PORT} is taken")
    yield server
    server.stop()


def snapshot_app() -> PoppyApp:
    return make_app(URL, 1_000_000, 2, port_lister=fixed_ports, live_period_s=0)


async def still(pilot: Any) -> None:
    for widget in pilot.app.main.query(Input):
        widget.cursor_blink = False
    await pilot.pause(0.2)


async def scanned(pilot: Any) -> None:
    screen = pilot.app.main
    # A scan of every ID over TCP; late in the whole suite (one long process, a loaded machine)
    # it was seen to take over 10 s. What is compared is the screen after it, not its speed.
    await wait_for(pilot, lambda: screen.last_scan is not None, timeout_s=60.0, what="scan")
    await still(pilot)


async def motor_open(pilot: Any) -> None:
    await scanned(pilot)
    screen = pilot.app.main
    tree = screen.query_one(MotorTree)
    node = next(n for n in tree._motors.values() if n.data is not None and n.data.id == 1)
    tree.select_node(node)
    table = screen.query_one(ControlTableView)
    await wait_for(pilot, lambda: table.row_count > 0, what="table")
    panel = screen.query_one(MotorPanel)
    for position in (0.0, 5.0, 10.0, 15.0, 10.0, 5.0):
        panel.post_message(LiveSampled(panel.motor, LiveValues(position, 0.0, 0.0, 35.0, 7.4)))
    await still(pilot)


async def robot_open(pilot: Any) -> None:
    await scanned(pilot)
    await pilot.press("f3")
    panel = pilot.app.main.query_one(RobotPanel)
    panel.query_one("#robot-source", Input).value = "ergo-jr"
    panel.open("ergo-jr", True)
    await wait_for(pilot, lambda: panel.robot is not None, what="robot")
    await pilot.pause(0.3)
    panel.robot.stop_sync()  # freeze the caches: the snapshot must not depend on timing
    panel.refresh_table()
    pilot.app.clear_notifications()
    await still(pilot)
    await pilot.pause(0.3)


def test_scan_screen(snap_compare: Any, tcp_server: EmulatorServer) -> None:
    assert snap_compare(snapshot_app(), terminal_size=SIZE, run_before=scanned)


def test_motor_panel(snap_compare: Any, tcp_server: EmulatorServer) -> None:
    assert snap_compare(snapshot_app(), terminal_size=SIZE, run_before=motor_open)


def test_robot_tab(snap_compare: Any, tcp_server: EmulatorServer) -> None:
    assert snap_compare(snapshot_app(), terminal_size=SIZE, run_before=robot_open)
