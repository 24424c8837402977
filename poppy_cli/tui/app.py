"""The poppy TUI application and its ``make_app`` factory."""
# ruff: noqa: TID253  (the TUI package is only imported by `poppy tui`, lazily)

from __future__ import annotations

import logging
from collections.abc import Sequence
from typing import ClassVar

from textual import on
from textual.app import App
from textual.binding import Binding, BindingType
from textual.notifications import SeverityLevel

from poppy_cli.tui.busio import BusPool
from poppy_cli.tui.messages import BusFailed, RobotOpened
from poppy_cli.tui.screens.main import MainScreen
from poppy_cli.tui.widgets.motor_tree import MotorTree
from poppy_cli.tui.widgets.ports import PortLister, PortsPanel
from poppy_cli.tui.widgets.robot_panel import RobotPanel
from poppy_cli.tui.widgets.scan import ScanPanel
from poppy_core.bus import PortInfo, list_ports
from poppy_core.emulator.link import SCHEME as LINK_SCHEME

logger = logging.getLogger(__name__)

LIVE_PERIOD_S = 0.05
"""Live view period (20 Hz)."""


class PoppyApp(App[None]):
    """Herborist's successor: find motors, set them up, watch them, drive a robot."""

    CSS_PATH = "poppy.tcss"
    TITLE = "poppy"
    SUB_TITLE = "Dynamixel motors"
    BINDINGS: ClassVar[list[BindingType]] = [Binding("q", "quit", "Quit")]

    def __init__(
        self,
        *,
        port: str | None = None,
        baudrate: int | None = None,
        protocol: int | None = None,
        sim: bool = False,
        virtual_ports: Sequence[str] = (),
        port_lister: PortLister = list_ports,
        live_period_s: float = LIVE_PERIOD_S,
        robot_source: str | None = None,
    ) -> None:
        super().__init__()
        self.pool = BusPool()
        self.start_port = port
        self.start_baudrate = baudrate
        self.start_protocol = protocol
        self.sim = sim
        self.virtual_ports = list(virtual_ports)
        self.port_lister = port_lister
        self.live_period_s = live_period_s
        self.robot_source = robot_source
        self.scan_robot = False
        """Scan the buses of the robot opened at start (``sim``): one robot per session."""
        self.main = MainScreen(self.pool, port_lister, live_period_s)

    def on_mount(self) -> None:
        self.push_screen(self.main)
        self.call_after_refresh(self._start)

    def _start(self) -> None:
        ports = self.main.query_one(PortsPanel)
        for url in self.virtual_ports:
            ports.add_virtual(url, select=False)
        baudrates = [self.start_baudrate] if self.start_baudrate else None
        protocols = [self.start_protocol] if self.start_protocol else None
        robot = self.robot_source
        if self.sim and robot is None:
            robot = "ergo-jr"
        if robot is not None:
            # The Bus and Motor tabs then scan this robot's own virtual buses (``_robot_opened``):
            # a dance started in the Robot tab is what the Motor tab shows.
            self.scan_robot = self.start_port is None
            self.main.query_one(RobotPanel).open(robot, self.sim)
        if self.start_port is not None:
            self.scan_at_start([self.start_port], baudrates, protocols)

    def scan_at_start(
        self, ports: list[str], baudrates: list[int] | None, protocols: list[int] | None
    ) -> None:
        """List ``ports`` in the Bus tab, scan them and focus the motor tree."""
        panel = self.main.query_one(ScanPanel)
        for port in ports:
            self.main.query_one(PortsPanel).add_virtual(port)
        panel.set_choice(baudrates, protocols)
        request = panel.request()
        if not isinstance(request, str):
            self.main.start_scan(ports, request)
        self.main.query_one(MotorTree).focus()

    @on(RobotOpened)
    def _robot_opened(self, message: RobotOpened) -> None:
        """Scan the buses of the robot opened at start that are linked in this process (its
        emulators): a real serial port is left to the robot, which holds it."""
        if not self.scan_robot:
            return
        self.scan_robot = False
        buses = [
            bus for bus in message.robot.buses.values() if bus.port.startswith(f"{LINK_SCHEME}://")
        ]
        if buses:
            self.scan_at_start(
                [bus.port for bus in buses],
                sorted({bus.baudrate for bus in buses}),
                sorted({bus.protocol for bus in buses}),
            )

    def notify(
        self,
        message: str,
        *,
        title: str = "",
        severity: SeverityLevel = "information",
        timeout: float | None = None,
        markup: bool = True,
    ) -> None:
        """Notifications carry file, port, motor and move names and error text: shown literally,
        never read as markup (``markup`` is ignored)."""
        super().notify(message, title=title, severity=severity, timeout=timeout, markup=False)

    @on(BusFailed)
    def _failed(self, message: BusFailed) -> None:
        self.notify(message.text, severity="error", timeout=6)

    def on_unmount(self) -> None:
        self.main.abort_event.set()
        self.pool.close()


def make_app(
    port: str | None = None,
    baudrate: int | None = None,
    protocol: int | None = None,
    sim: bool = False,
    *,
    virtual_ports: Sequence[str] = (),
    port_lister: PortLister | None = None,
    live_period_s: float = LIVE_PERIOD_S,
    robot_source: str | None = None,
) -> PoppyApp:
    """Build the TUI.

    Args:
        port: a bus to open straight away (it is scanned at start).
        baudrate: the rate to scan ``port`` at (None: every standard rate).
        protocol: the protocol to scan ``port`` in (None: both).
        sim: open a virtual Ergo Jr in the Robot tab (``robot_source`` when given: its motors
            served by emulators) and scan its buses in the Bus tab: one robot for every tab.
        virtual_ports: extra virtual buses listed (pty paths, ``socket://`` URLs).
        port_lister: lists the serial ports (tests pass fixed data); None uses ``list_ports``.
        live_period_s: live view period; 0 turns the live view off.
        robot_source: a profile name or config file to open in the robot tab.

    Returns:
        The app; call ``run()`` (or ``run_test()`` in tests).
    """
    lister: PortLister = port_lister if port_lister is not None else _list_ports
    return PoppyApp(
        port=port,
        baudrate=baudrate,
        protocol=protocol,
        sim=sim,
        virtual_ports=virtual_ports,
        port_lister=lister,
        live_period_s=live_period_s,
        robot_source=robot_source,
    )


def _list_ports() -> list[PortInfo]:
    return list_ports()
