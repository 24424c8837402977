"""Responsiveness with a 25-motor virtual bus: live refresh rate, key latency while scanning."""

from __future__ import annotations

import time

from textual.widgets import TabbedContent  # noqa: TID253  (a TUI test)

from poppy_cli.tui.app import make_app
from poppy_cli.tui.widgets.live import LivePanel
from poppy_cli.tui.widgets.motor_tree import MotorTree
from poppy_core.emulator import Endpoint
from tests.helpers.tui import no_ports, run_async, wait_for

SIZE = (100, 40)


@run_async
async def test_live_view_refreshes_at_10_hz(big_server: Endpoint) -> None:
    app = make_app(big_server.url, 1_000_000, 1, port_lister=no_ports)
    async with app.run_test(size=SIZE) as pilot:
        screen = app.main
        await wait_for(pilot, lambda: screen.last_scan is not None, timeout_s=20)
        tree = screen.query_one(MotorTree)
        assert len(tree.motors) == 25
        first = next(n for n in tree._motors.values() if n.data is not None and n.data.id == 1)
        tree.select_node(first)
        live = screen.query_one(LivePanel)
        await wait_for(pilot, lambda: live.samples > 0, what="first live sample")
        # The view asks every 0.1 s (10 Hz on a quiet machine: printed, not asserted, since a
        # loaded 2-core machine halves it: speed belongs to the benchmarks). What must hold is
        # that it keeps refreshing on a 25-motor bus: ten more samples arrive.
        assert app.live_period_s <= 0.1
        start_samples, start = live.samples, time.monotonic()
        await wait_for(pilot, lambda: live.samples >= start_samples + 10, what="ten more samples")
        rate_hz = (live.samples - start_samples) / (time.monotonic() - start)
        print(f"live refresh: {rate_hz:.1f} Hz")


@run_async
async def test_keys_answer_quickly_while_scanning(big_server: Endpoint) -> None:
    app = make_app(big_server.url, port_lister=no_ports, live_period_s=0)  # every rate, both
    async with app.run_test(size=SIZE) as pilot:
        screen = app.main
        await pilot.pause(0.2)
        assert screen.scanning
        tabs = ("robot", "bus", "motor")
        delays = []
        for i in range(6):
            start = time.monotonic()
            await pilot.press(("f3", "f1", "f2")[i % 3])
            assert screen.query_one("#tabs", TabbedContent).active == tabs[i % 3]
            assert screen.scanning  # switched while the scan runs: not queued behind it
            delays.append(screen.tab_switched_s - start)
        assert screen.scanning
        screen.action_abort()
        print(
            f"key latency while scanning: max {max(delays) * 1000:.0f} ms, "
            f"mean {sum(delays) / len(delays) * 1000:.0f} ms"
        )
        # The goal is 100 ms (a quiet machine gives tens of ms; `python -m bench timing`
        # measures it); on a loaded 2-core machine a key may wait for the CPU for a second or
        # more. What must hold here is that keys are not queued behind the scan (which takes
        # tens of seconds at every rate): each tab switched while the scan still ran (above).
