"""Ports panel: serial ports refreshed live, adapter and warnings, virtual buses added by hand."""
# ruff: noqa: TID253  (the TUI package is only imported by `poppy tui`, lazily)

from __future__ import annotations

from collections.abc import Callable

from textual import on, work
from textual.app import ComposeResult
from textual.containers import Vertical
from textual.widgets import Input, SelectionList, Static
from textual.widgets.selection_list import Selection

from poppy_cli.tui.messages import BusFailed, PortsListed
from poppy_cli.tui.widgets.toggles import MarkedList
from poppy_core.bus import PortInfo
from poppy_core.errors import PoppyError

PortLister = Callable[[], list[PortInfo]]
REFRESH_S = 2.0


def port_label(info: PortInfo) -> str:
    """One line for a port: device, adapter (or description) and a warning mark."""
    name = info.adapter or info.description or "serial port"
    warn = " ⚠" if info.advice else ""
    return f"{info.device}  {name}{warn}"


class PortsPanel(Vertical):
    """Ports to scan (space ticks one), refreshed every 2 s, plus virtual buses typed in."""

    def __init__(self, lister: PortLister, *, id: str | None = None) -> None:
        super().__init__(id=id)
        self._lister = lister
        self._infos: dict[str, PortInfo] = {}
        self._virtual: list[str] = []

    def compose(self) -> ComposeResult:
        yield Static("Ports [dim](space ticks)[/]", classes="title")
        yield MarkedList[str](id="port-list")
        yield Static("", id="port-advice")
        yield Input(placeholder="virtual bus: /dev/pts/N or socket://host:port", id="virtual")

    def on_mount(self) -> None:
        self.refresh_ports()
        self.set_interval(REFRESH_S, self.refresh_ports)

    @work(thread=True, exclusive=True, group="ports", exit_on_error=False)
    def refresh_ports(self) -> None:
        """List the serial ports in a thread (reading sysfs may block a moment)."""
        try:
            ports = self._lister()
        except (PoppyError, OSError) as exc:
            self.post_message(BusFailed(f"cannot list ports: {exc}"))
            return
        self.post_message(PortsListed(ports))

    @on(PortsListed)
    def _ports_listed(self, message: PortsListed) -> None:
        message.stop()
        infos = {info.device: info for info in message.ports}
        if infos.keys() == self._infos.keys() and list(infos.values()) == list(
            self._infos.values()
        ):
            return
        self._infos = infos
        self._rebuild()

    def _rebuild(self) -> None:
        plist = self.query_one("#port-list", SelectionList)
        chosen = set(plist.selected)
        plist.clear_options()
        options = [
            Selection(port_label(info), info.device, info.device in chosen)
            for info in self._infos.values()
        ]
        options += [
            Selection(f"{url}  virtual", url, url in chosen)
            for url in self._virtual
            if url not in self._infos
        ]
        plist.add_options(options)
        self._show_advice()

    def add_virtual(self, url: str, *, select: bool = True) -> None:
        """Add a virtual bus (pty path or ``socket://`` URL) to the list, ticked."""
        url = url.strip()
        if not url:
            return
        if url not in self._virtual and url not in self._infos:
            self._virtual.append(url)
            self._rebuild()
        if select:
            self.query_one("#port-list", SelectionList).select(url)

    @property
    def selected(self) -> list[str]:
        """The ticked ports."""
        return list(self.query_one("#port-list", SelectionList).selected)

    @on(Input.Submitted, "#virtual")
    def _virtual_typed(self, event: Input.Submitted) -> None:
        self.add_virtual(event.value)
        event.input.value = ""

    @on(SelectionList.SelectionHighlighted, "#port-list")
    def _highlighted(self) -> None:
        self._show_advice()

    def _show_advice(self) -> None:
        plist = self.query_one("#port-list", SelectionList)
        advice = self.query_one("#port-advice", Static)
        lines: list[str] = []
        if plist.highlighted is not None and plist.option_count:
            device = plist.get_option_at_index(plist.highlighted).value
            info = self._infos.get(str(device))
            if info is not None:
                if info.latency_timer_ms is not None:
                    lines.append(f"latency timer {info.latency_timer_ms} ms")
                lines += [f"⚠ {hint}" for hint in info.advice]
        elif not self._infos and not self._virtual:
            lines.append("no serial port: plug an adapter or add a virtual bus")
        advice.update("\n".join(lines))
