"""Start-up holds when replies come late (an emulator starved by a loaded machine): motors silent
through their first pings are asked again patiently, and the return delays and angle limits the
user agreed to are written, with no warning."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from poppy_core import from_profile
from poppy_core.bus import DxlBus
from poppy_core.emulator import VirtualBus, VirtualMotor, serve_link
from poppy_core.emulator.bus_servers import EmulatorServer
from poppy_core.models import model_by_name
from poppy_core.robot import Motor, ReturnDelayIssue
from poppy_core.robot.startup import PRESENCE_RETRIES, STARTUP_PING_RETRIES, check_presence
from tests.helpers.late_replies import LateFirst

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


def test_a_motor_silent_through_its_first_pings_is_asked_again_patiently() -> None:
    # Motor 1's four start-up pings are all answered 60 ms late (the first ping's wait is 10 ms
    # a try): the robot is built all the same, every motor online.
    motors = [VirtualMotor(XL320, motor_id, 1_000_000) for motor_id in range(1, 7)]
    with (
        serve_link(VirtualBus(motors, 2, faults=LateFirst(4, 0.06))) as server,
        from_profile("ergo-jr", port=str(server.url), sensors=False) as robot,
    ):
        assert [m.online for m in robot.motors] == [True] * 6


def _pings_to_presence(spec: list[int], unplugged: set[int]) -> tuple[list[str], int]:
    """check_presence of motors 1-6 on a bus holding ``spec``: (problems, packets the bus heard)."""
    bus = VirtualBus([VirtualMotor(XL320, i, 1_000_000) for i in spec], 2)
    for motor_id in unplugged:
        bus.unplug(motor_id)
    wanted = [Motor(f"m{i}", XL320, i) for i in range(1, 7)]
    with serve_link(bus) as server, DxlBus(str(server.url), 1_000_000, 2) as line:
        problems = check_presence(line, "c", wanted)
    return problems, bus.packets_received


def test_a_missing_motor_is_asked_patiently_once_more() -> None:
    problems, heard = _pings_to_presence([1, 2, 3, 4, 5, 6], unplugged={3})
    assert len(problems) == 1
    assert "missing motors m3 (id 3) (searched" in problems[0]
    # five motors answer their first ping; m3 is pinged 1 + 3 retries, then 1 + 1 patiently
    assert heard == 5 + (1 + STARTUP_PING_RETRIES) + (1 + PRESENCE_RETRIES)


def test_an_empty_bus_costs_one_patient_ask_not_one_a_motor() -> None:
    problems, heard = _pings_to_presence([9], unplugged=set())
    assert (
        "missing motors m1 (id 1), m2 (id 2), m3 (id 3), m4 (id 4), m5 (id 5), m6 (id 6)"
        in (problems[0])
    )
    assert heard == 6 * (1 + STARTUP_PING_RETRIES) + (1 + PRESENCE_RETRIES)
