"""Start-up writes the user agreed to hold when replies come late (an emulator starved by a loaded
machine): the return delays and angle limits are written, with no warning."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from poppy_core import from_profile
from poppy_core.emulator import VirtualBus, VirtualMotor, serve_link
from poppy_core.emulator.bus_servers import EmulatorServer
from poppy_core.models import model_by_name
from poppy_core.robot import ReturnDelayIssue

XL320 = model_by_name("XL-320")
# Later than the bus's usual floor (10 ms, one retry) for every reply, as beside four busy loops.
LATE_S = 0.03


@pytest.fixture
def line() -> Iterator[tuple[VirtualBus, str]]:
    """Six stiff XL-320 as from the factory (return delay 500 µs), served on the in-process link."""
    motors = [VirtualMotor(XL320, motor_id, 1_000_000) for motor_id in range(1, 7)]
    for motor in motors:
        motor.table.set("torque_enable", 1)  # the XL-320 locks its EEPROM while stiff
    bus = VirtualBus(motors, 2)
    server: EmulatorServer = serve_link(bus)
    yield bus, str(server.url)
    server.stop()


def test_writes_agreed_to_at_start_up_wait_for_late_replies(
    line: tuple[VirtualBus, str], caplog: pytest.LogCaptureFixture
) -> None:
    bus, url = line

    def agree_then_starve(issues: list[ReturnDelayIssue]) -> bool:
        bus.extra_delay_s = LATE_S  # from the question on, every reply comes late
        return True

    with (
        caplog.at_level("WARNING"),
        from_profile("ergo-jr", port=url, sensors=False, fix_return_delay=agree_then_starve),
    ):
        bus.extra_delay_s = 0.0
    assert [r.getMessage() for r in caplog.records if r.levelname == "WARNING"] == []
    assert [m.table.get("return_delay_time") for m in bus.motors] == [0] * 6
    assert [m.table.get("torque_enable") for m in bus.motors] == [1] * 6  # still stiff


def test_first_state_waits_for_late_replies(line: tuple[VirtualBus, str]) -> None:
    bus, url = line
    bus.extra_delay_s = LATE_S
    with from_profile("ergo-jr", port=url, sensors=False, fix_return_delay=False) as robot:
        bus.extra_delay_s = 0.0
        assert [m.compliant for m in robot.motors] == [False] * 6
