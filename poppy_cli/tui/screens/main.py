"""Main screen: Bus tab (ports, scan, found motors), Motor tab (panel), Robot tab."""
# ruff: noqa: TID253  (the TUI package is only imported by `poppy tui`, lazily)

from __future__ import annotations

import threading
import time
from typing import ClassVar

from textual import on, work
from textual.app import ComposeResult
from textual.binding import Binding, BindingType
from textual.containers import Horizontal, VerticalScroll
from textual.screen import Screen
from textual.widgets import Footer, Header, TabbedContent, TabPane
from textual.worker import get_current_worker

from poppy_cli.tui.busio import BusPool, MotorRef
from poppy_cli.tui.messages import MotorFound, MotorMoved, ScanFinished, ScanProgressed
from poppy_cli.tui.widgets.motor_panel import MotorPanel
from poppy_cli.tui.widgets.motor_tree import MotorTree
from poppy_cli.tui.widgets.ports import PortLister, PortsPanel
from poppy_cli.tui.widgets.robot_panel import RobotPanel
from poppy_cli.tui.widgets.scan import ScanPanel, ScanRequest
from poppy_core.bus import FoundMotor, ScanProgress, is_virtual_port, scan
from poppy_core.errors import PoppyError

PROGRESS_EVERY_S = 0.05
TAB_FOCUS = {"bus": "#tree", "motor": "#control-table", "robot": "#robot-table"}
# An emulator in this process shares the interpreter with the UI: allow it late replies.
VIRTUAL_SCAN_LATENCY_S = 0.005


class BusView(Horizontal):
    """The Bus tab: the motor tree, then ports and scan options (ctrl+s shown in its footer)."""

    BINDINGS: ClassVar[list[BindingType]] = [Binding("ctrl+s", "screen.scan", "Scan")]


class MainScreen(Screen[None]):
    """Three tabs; the bus work runs in thread workers and reports with messages."""

    BINDINGS: ClassVar[list[BindingType]] = [
        # The tab labels show F1-F3 (the footer has no room for them at 80 columns).
        Binding("f1", "tab('bus')", "Bus", show=False),
        Binding("f2", "tab('motor')", "Motor", show=False),
        Binding("f3", "tab('robot')", "Robot", show=False),
        Binding("tab", "app.focus_next", "Next"),
        Binding("ctrl+s", "scan", "Scan", show=False),  # shown by the Bus tab (BusView)
        Binding("escape", "abort", "Abort scan", show=False),
        Binding("f4", "setup", "Set up a kit", show=False),
    ]

    def __init__(self, pool: BusPool, lister: PortLister, live_period_s: float) -> None:
        super().__init__()
        self.pool = pool
        self.lister = lister
        self.live_period_s = live_period_s
        self.abort_event = threading.Event()
        self.scanning = False
        self.last_scan: ScanFinished | None = None
        self.tab_switched_s = 0.0
        """When a tab key was last handled (monotonic; the responsiveness test reads it)."""

    def compose(self) -> ComposeResult:
        yield Header()
        with TabbedContent(initial="bus", id="tabs"):
            # The tree first: one Tab from the tab bar reaches it (focus goes left to right).
            with TabPane("Bus F1", id="bus"), BusView():
                yield MotorTree(id="tree")
                with VerticalScroll(id="bus-side"):
                    yield PortsPanel(self.lister, id="ports")
                    yield ScanPanel(id="scan-panel")
            with TabPane("Motor F2", id="motor"):
                yield MotorPanel(self.pool, self.live_period_s, id="motor-panel")
            with TabPane("Robot F3", id="robot"):
                yield RobotPanel(id="robot-panel")
        yield Footer(compact=True)

    def action_setup(self) -> None:
        """Set a kit's motors up, one at a time (the flow of `poppy setup motors`): the
        robot's profile (else the user's, else ergo-jr) on the first port chosen."""
        from poppy_cli.settings import resolve
        from poppy_cli.tui.screens.setup import SetupScreen
        from poppy_core.robot.guided_setup import GuidedSetup
        from poppy_core.robot.profiles import load_profile

        chosen = self.query_one(PortsPanel).selected
        port = chosen[0] if chosen else resolve(None, None).port
        if port is None:
            self.notify("choose the port of the kit's bus in the Bus tab first", severity="error")
            return
        source = getattr(self.app, "robot_source", None)
        profile = source or resolve(None, None).profile or "ergo-jr"
        try:
            flow = GuidedSetup(load_profile(profile), port)
        except PoppyError as exc:
            self.notify(str(exc), severity="error")
            return
        self.app.push_screen(SetupScreen(flow, profile))

    def action_tab(self, tab: str) -> None:
        """Show a tab and focus its main widget (focus left in a hidden tab would pull it back)."""
        self.query_one(TabbedContent).active = tab
        self.query_one(TAB_FOCUS[tab]).focus()
        self.tab_switched_s = time.monotonic()

    # -- scan ------------------------------------------------------------------------------

    def start_scan(self, ports: list[str], request: ScanRequest) -> None:
        """Clear the results and scan ``ports`` in a thread worker."""
        if not ports:
            self.notify("tick a port (or add a virtual bus) first", severity="warning")
            return
        self.query_one(MotorTree).clear_motors()
        self.abort_event.clear()
        self.scanning = True
        self.query_one(ScanPanel).running(True)
        self.run_scan(ports, request)

    def action_scan(self) -> None:
        """Scan the ticked ports with the chosen options."""
        request = self.query_one(ScanPanel).request()
        if isinstance(request, str):
            self.notify(request, severity="warning")
            return
        self.start_scan(self.query_one(PortsPanel).selected, request)

    def action_abort(self) -> None:
        """Stop the running scan."""
        self.abort_event.set()
        for worker in self.workers:
            if worker.group == "scan":
                worker.cancel()

    @on(ScanPanel.Requested)
    def _requested(self, message: ScanPanel.Requested) -> None:
        if message.request is None:
            self.action_abort()
        else:
            self.start_scan(self.query_one(PortsPanel).selected, message.request)

    @work(thread=True, exclusive=True, group="scan", exit_on_error=False)
    def run_scan(self, ports: list[str], request: ScanRequest) -> None:
        """Scan each port (holding it, so the live view waits); post progress and finds."""
        worker = get_current_worker()
        start = time.monotonic()
        last = 0.0
        found = 0

        def should_abort() -> bool:
            return worker.is_cancelled or self.abort_event.is_set()

        def progress(step: ScanProgress) -> None:
            nonlocal last
            now = time.monotonic()
            if now - last >= PROGRESS_EVERY_S:
                last = now
                self.post_message(ScanProgressed(step))

        def on_found(motor: FoundMotor) -> None:
            nonlocal found
            found += 1
            self.post_message(MotorFound(motor))

        for port in ports:
            if should_abort():
                break
            try:
                with self.pool.exclusive(port):
                    scan(
                        port,
                        request.baudrates,
                        request.protocols,
                        request.ids,
                        progress=progress,
                        should_abort=should_abort,
                        on_found=on_found,
                        latency_s=VIRTUAL_SCAN_LATENCY_S if is_virtual_port(port) else None,
                    )
            except PoppyError as exc:
                self.app.call_from_thread(
                    self.notify, f"scan of {port} failed: {exc}", severity="error"
                )
        self.post_message(ScanFinished(found, should_abort(), time.monotonic() - start))

    @on(ScanProgressed)
    def _progress(self, message: ScanProgressed) -> None:
        p = message.progress
        self.query_one(ScanPanel).show_progress(
            p.done, p.total, f"{p.baudrate:,} bps P{p.protocol} · {p.found} found"
        )

    @on(MotorFound)
    def _found(self, message: MotorFound) -> None:
        m = message.motor
        self.query_one(MotorTree).add_motor(
            MotorRef(m.port, m.baudrate, m.protocol, m.id, m.model, m.firmware)
        )

    @on(ScanFinished)
    def _finished(self, message: ScanFinished) -> None:
        self.scanning = False
        self.last_scan = message
        panel = self.query_one(ScanPanel)
        panel.running(False)
        state = "aborted" if message.aborted else "done"
        panel.show_progress(1, 1, f"scan {state}: {message.found} motor(s)")
        if message.aborted:
            self.notify(f"scan aborted: {message.found} motor(s) found")

    # -- motors ----------------------------------------------------------------------------

    @on(MotorTree.Opened)
    def _opened(self, message: MotorTree.Opened) -> None:
        self.query_one(MotorPanel).open(message.motor, message.marked)
        self.action_tab("motor")

    @on(MotorMoved)
    def _moved(self, message: MotorMoved) -> None:
        self.query_one(MotorTree).replace_motor(message.old, message.new)
