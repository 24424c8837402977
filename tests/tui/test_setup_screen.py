"""The TUI's setup screen (F4) walks a kit's motors one at a time, as `poppy setup motors`."""

from __future__ import annotations

from textual.widgets import Log  # noqa: TID253  (a TUI test)

from poppy_cli.tui.app import make_app
from poppy_cli.tui.screens.setup import SetupScreen
from poppy_cli.tui.widgets.ports import PortsPanel
from poppy_core.emulator import serve_link
from poppy_core.robot.guided_setup import motor_targets
from poppy_core.robot.profiles import load_profile
from tests.cli.test_setup_doctor import kit
from tests.helpers.tui import no_ports, run_async, wait_for

SIZE = (110, 30)


@run_async
async def test_the_setup_screen_walks_a_kit_plugged_one_at_a_time() -> None:
    bus = kit()
    with serve_link(bus) as server:
        app = make_app(port_lister=no_ports, live_period_s=0)
        async with app.run_test(size=SIZE) as pilot:
            app.main.query_one(PortsPanel).add_virtual(server.url)
            await pilot.press("f4")
            screen = app.screen
            assert isinstance(screen, SetupScreen)
            # nothing plugged yet: the step fails, says why, and the prompt stays
            assert screen.prompt == "plug only m1 (XL-320) on the bus and press Enter"
            await pilot.press("enter")
            await wait_for(pilot, lambda: bool(screen.errors), 30, "the refusal")
            assert "is m1 plugged and powered?" in screen.errors[0]
            assert screen.prompt.startswith("plug only m1 ")
            for place in range(1, 7):
                assert screen.prompt == f"plug only m{place} (XL-320) on the bus and press Enter"
                if place > 1:
                    bus.detach(place - 1)
                bus.attach(place)
                await pilot.press("enter")
                await wait_for(
                    pilot,
                    lambda n=place: len(screen.outcomes) == n or len(screen.errors) > 1,  # type: ignore[misc]
                    30,
                    f"m{place} set up",
                )
                assert len(screen.errors) == 1, screen.errors
            assert screen.done and "poppy doctor --profile ergo-jr" in screen.prompt
            log = "\n".join(screen.query_one("#setup-log", Log).lines)
            assert "m3: found as ID 1 at 1000000 bps; set id" in log and "next: m4" in log
    for place in range(1, 7):
        bus.attach(place)
    targets = motor_targets(load_profile("ergo-jr"))
    assert [m.id for m in bus.motors] == [t.id for t in targets]
    assert all(m.table.get("return_delay_time") == 0 for m in bus.motors)
