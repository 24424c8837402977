"""Scans and searches on adapters slower than assumed, late model reads, ports that cannot open."""

from __future__ import annotations

from typing import TYPE_CHECKING

import pytest

from poppy_core.bus import DxlBus, find_port, locate, scan
from poppy_core.emulator import FaultInjector, VirtualBus, VirtualMotor, serve_link, serve_pty
from poppy_core.errors import PortError
from poppy_core.models import model_by_name
from poppy_core.robot import Motor
from poppy_core.robot.startup import check_presence
from tests.helpers.bus import loaded_reply_floor_s
from tests.helpers.late_replies import DropFirst, LateAfter, LateFirst

if TYPE_CHECKING:
    from tests.helpers.bus import Emulate

SLOW = {"wire_timing": True, "latency_s": 0.008}  # an adapter holding replies 8 ms


def _found(found: list) -> list[tuple[int, int]]:  # type: ignore[type-arg]
    return sorted((f.id, f.baudrate) for f in found)


@pytest.mark.parametrize("broadcast", [True, False])
def test_scan_on_a_slow_adapter_reports_the_right_rate(emulate: Emulate, broadcast: bool) -> None:
    with emulate("XL-320:1-3", protocol=2, **SLOW) as (_, url):
        found = scan(url, [1_000_000, 2_000_000], [2], ids=range(6), broadcast=broadcast)
    assert _found(found) == [(1, 1_000_000), (2, 1_000_000), (3, 1_000_000)]
    assert all(f.model == "XL-320" for f in found)


def test_protocol_1_scan_on_a_slow_adapter(emulate: Emulate) -> None:
    with emulate("MX-28:1-2", **SLOW) as (_, url):
        found = scan(url, [1_000_000, 500_000, 400_000], [1], ids=range(4))
    assert _found(found) == [(1, 1_000_000), (2, 1_000_000)]
    assert all(f.model == "MX-28" for f in found)


def test_find_port_on_a_slow_adapter(emulate: Emulate) -> None:
    with emulate("XL-320:1-2", protocol=2, wire_timing=True, latency_s=0.03) as (_, url):
        assert find_port([1, 2], [url]) == (url, 1_000_000, 2)


def test_locate_on_a_slow_adapter(emulate: Emulate) -> None:
    slow = emulate("XL-320:1-2", protocol=2, wire_timing=True, latency_s=0.03)
    with slow as (_, url), DxlBus(url, 57_600, 2) as bus:
        assert locate(bus, 2) == 1_000_000
        assert bus.baudrate == 1_000_000


class DropOnce(FaultInjector):
    """Loses the reply numbered ``which`` (1 = the first), as a reply that came too late."""

    def __init__(self, which: int) -> None:
        super().__init__()
        self.which = which
        self.count = 0

    def filter_reply(self, data: bytes) -> bytes | None:
        self.count += 1
        return None if self.count == self.which else data


def test_a_late_model_read_after_a_ping_is_retried() -> None:
    # Protocol 1 pings carry no model: it is read right after. A scan pings without retry;
    # the model read must still get the usual retry, not record an unknown model.
    # On the in-process link: a pty's emulator thread, late on a busy machine, made the ping's
    # own reply late, which is another test (the subject here is the model read's retry).
    motor = VirtualMotor(model_by_name("MX-28"), 7, 1_000_000)
    virtual = VirtualBus([motor], 1, faults=DropOnce(2))
    with serve_link(virtual) as server:
        (found,) = scan(server.url, [1_000_000], [1], ids=[7])
    assert (found.id, found.model, found.model_number) == (7, "MX-28", 29)


def test_find_port_on_a_port_that_cannot_open_is_a_port_error(tmp_path: object) -> None:
    with pytest.raises(PortError, match="no such port"):
        find_port([3], ["/dev/ttyUSB_poppy_missing_3"])
    with pytest.raises(PortError, match="no port could be opened"):
        find_port([3], ["/dev/ttyUSB_poppy_missing_4", "/dev/ttyUSB_poppy_missing_5"])


def test_a_robot_is_not_refused_for_a_motor_late_twice_at_startup() -> None:
    # Two lost replies in a row exceed the bus's single retry; the startup check retries more.
    motor = VirtualMotor(model_by_name("MX-28"), 7, 1_000_000)
    with (
        serve_pty(VirtualBus([motor], 1, faults=DropFirst(2))) as server,
        # the emulator thread's replies late on a busy machine are not the lost ones counted here
        DxlBus(server.url, 1_000_000, 1, min_timeout_s=loaded_reply_floor_s()) as bus,
    ):
        assert bus.retries < 2
        robot_motor = Motor("m7", model_by_name("MX-28"), 7)
        assert check_presence(bus, "c", [robot_motor]) == []
        assert robot_motor.online


@pytest.mark.parametrize(
    "rates",
    [[1_000_000], [2_000_000, 1_000_000], [1_000_000, 2_000_000], [57_600, 1_000_000, 2_000_000]],
)
def test_two_late_empty_broadcasts_do_not_hide_the_motors(rates: list[int]) -> None:
    # Both broadcast pings' replies (3 motors x 2) come far past their deadline: the pair
    # agrees and the line stays clean, but the silence was lateness, not an empty bus.
    motors = [VirtualMotor(model_by_name("XL-320"), i, 1_000_000) for i in (1, 2, 3)]
    with serve_link(VirtualBus(motors, 2, faults=LateFirst(6, 0.025))) as server:
        found = scan(server.url, rates, [2])
    assert _found(found) == [(1, 1_000_000), (2, 1_000_000), (3, 1_000_000)]
    assert all(f.model == "XL-320" for f in found)


@pytest.mark.parametrize(("model", "protocol"), [("MX-28", 1), ("XL-320", 2)])
def test_a_motor_late_when_asked_again_is_not_dropped(model: str, protocol: int) -> None:
    # A factory-new motor (57,600 bps) found at the second rate tried is asked again before it
    # is reported; the OS runs its emulator 50 ms late right then (the replies after the ping
    # and the model read, or the two broadcast pings). It is not taken for a late echo from the
    # rate before and dropped (`poppy scan --all-bauds` in CI): asked patiently, it answers.
    motor = VirtualMotor(model_by_name(model), 1, 57_600)
    with serve_link(VirtualBus([motor], protocol, faults=LateAfter(2, 2, 0.05))) as server:
        found = scan(server.url, [1_000_000, 57_600, 19_200], [protocol], patient=False)
    assert _found(found) == [(1, 57_600)]


@pytest.mark.parametrize("skip", [1, 2, 3, 4])
def test_a_slow_adapter_s_scan_held_up_once_still_finds_every_motor(skip: int) -> None:
    # The emulator is held up 100 ms once (the replies after the first `skip` wait behind it)
    # while a slow adapter's scan asks its late replies again: a reply that came late behind
    # another, kept aside meanwhile, is asked in turn (CI beside four busy loops lost motor 2 so).
    motors = [VirtualMotor(model_by_name("MX-28"), i, 1_000_000) for i in (1, 2)]
    bus = VirtualBus(motors, 1, faults=LateAfter(skip, 1, 0.1), **SLOW)
    with serve_link(bus) as server:
        found = scan(server.url, [1_000_000, 500_000, 400_000], [1], ids=range(4))
    assert _found(found) == [(1, 1_000_000), (2, 1_000_000)]
