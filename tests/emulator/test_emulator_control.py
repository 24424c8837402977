"""Fault commands on running emulators (what `poppy emulate --control` and `--unplug` run)."""

from __future__ import annotations

import re
from collections.abc import Callable, Iterator

import pytest

from poppy_core.bus import DxlBus
from poppy_core.emulator import EmulatorServer, build_bus_from_spec, serve_tcp
from poppy_core.emulator.control import ControlError, EmulatorControl, ScheduledUnplug
from tests.helpers.bus import loaded_reply_floor_s
from tests.helpers.waiting import eventually


@pytest.fixture
def served() -> Iterator[tuple[EmulatorControl, EmulatorServer]]:
    server = serve_tcp(build_bus_from_spec("XL-320:1-3", protocol=2))
    control = EmulatorControl({"bus": server})
    yield control, server
    control.close()
    server.stop()


def _until(check: Callable[[], object], timeout_s: float = 3.0) -> bool:
    """``eventually``: the emulator's timers and threads run late on a busy machine."""
    return eventually(lambda: bool(check()), timeout_s)


def _answers(bus: DxlBus, motor_id: int) -> bool:
    """Whether ``motor_id`` answers a ping, as sure as a ping at the loaded floor and in half
    its time when it does not: the ping's tries wait no floor, then the line is listened to for
    the floor once (not once per try); a late reply of the motor counts as an answer."""
    floor = bus.min_timeout_s
    bus.min_timeout_s = 0.0
    try:
        if bus.ping(motor_id) is not None:
            return True
    finally:
        bus.min_timeout_s = floor
    return any(status.id == motor_id for status in bus.listen(floor))


def test_fault_commands_set_the_knobs(served: tuple[EmulatorControl, EmulatorServer]) -> None:
    control, server = served
    assert control.execute("corrupt 0.01") == "corrupt 0.01 on bus"
    assert control.execute("DROP 0.5 bus") == "drop 0.5 on bus"
    assert control.execute("delay 12") == "delay 12 ms on bus"
    assert (server.bus.corrupt_rate, server.bus.drop_rate) == (0.01, 0.5)
    assert server.bus.extra_delay_s == pytest.approx(0.012)
    assert "unplugged: none" in control.execute("status")
    assert control.execute("") == ""
    assert control.execute("help").startswith("commands:")


@pytest.mark.parametrize(
    ("line", "message"),
    [
        ("jump 3", "unknown command 'jump'"),
        ("unplug", "usage: unplug ID"),
        ("unplug 9", "no motor 9 (motors: 1, 2, 3)"),
        ("unplug 2 -1", "seconds 0-86400"),
        ("unplug 2 1e12", "seconds 0-86400"),
        ("corrupt 2", "between 0 and 1"),
        ("drop x", "between 0 and 1"),
        ("delay -3", "milliseconds 0-10000"),
        ("delay 1e309", "milliseconds 0-10000"),
        ("lose 1e12", "seconds 0-86400"),
        ("drop 0.1 other", "no bus 'other' (buses: bus)"),
        ("lose soon", "usage: lose"),
    ],
)
def test_bad_commands_are_one_line_errors(
    served: tuple[EmulatorControl, EmulatorServer], line: str, message: str
) -> None:
    control, _ = served
    with pytest.raises(ControlError, match=re.escape(message)) as caught:
        control.execute(line)
    assert "\n" not in str(caught.value)


def test_unplug_for_a_while_then_back(served: tuple[EmulatorControl, EmulatorServer]) -> None:
    control, server = served
    floor_s = loaded_reply_floor_s()
    with DxlBus(server.url, 1_000_000, 2, min_timeout_s=floor_s) as bus:
        # unplugged for longer than the ping that follows and its loaded floor, with a margin
        away_s = round(3 * floor_s, 1)
        assert control.execute(f"unplug 2 {away_s}") == f"motor 2 unplugged for {away_s:g} s"
        assert not _answers(bus, 2)
        assert _until(lambda: bus.ping(2) is not None)
        control.execute("unplug 3")
        assert not _answers(bus, 3) and bus.ping(1) is not None
        assert control.execute("plug 3") == "motor 3 plugged"
        assert bus.ping(3) is not None


def test_lose_takes_the_line_away(served: tuple[EmulatorControl, EmulatorServer]) -> None:
    control, server = served
    assert control.execute("lose 0.3") == "bus lost for 0.3 s"
    assert _until(lambda: not server.connected, 1.0)
    assert _until(lambda: server.connected)


def test_scheduled_unplugs() -> None:
    assert ScheduledUnplug.parse("3@10") == ScheduledUnplug(3, 10.0, None)
    assert ScheduledUnplug.parse("3@1.5+2") == ScheduledUnplug(3, 1.5, 2.0)
    for bad in ("3", "x@1", "3@", "3@-1", "3@1+", "3@nan"):
        with pytest.raises(ControlError, match="ID@SECONDS"):
            ScheduledUnplug.parse(bad)
    server = serve_tcp(build_bus_from_spec("XL-320:1-2", protocol=2))
    control = EmulatorControl({"bus": server})
    try:
        control.schedule([ScheduledUnplug(2, 0.0, 0.4)])
        # due at once: done before schedule returns (poppy emulate prints its url after it)
        assert server.bus.faults.is_unplugged(2)
        assert _until(lambda: not server.bus.faults.is_unplugged(2), 2.0)
        with pytest.raises(ControlError, match="no motor 7"):
            control.schedule([ScheduledUnplug(7, 0.0)])
    finally:
        control.close()
        server.stop()


def test_motors_sharing_an_id_are_plugged_by_their_place() -> None:
    server = serve_tcp(build_bus_from_spec("XL-320:1*3", protocol=2))
    control = EmulatorControl({"bus": server})
    try:
        assert [m.id for m in server.bus.motors] == [1, 1, 1]
        for place in (1, 2, 3):
            assert control.execute(f"unplug #{place}") == f"motor #{place} unplugged"
        assert "unplugged: #1, #2, #3" in control.execute("status")
        with DxlBus(server.url, protocol=2, min_timeout_s=loaded_reply_floor_s()) as bus:
            assert bus.broadcast_ping() == []
            assert control.execute("plug #2") == "motor #2 plugged"
            assert [p.id for p in bus.broadcast_ping()] == [1]
            server.bus.motors[1].table.set("id", 5)
            assert [p.id for p in bus.broadcast_ping()] == [5]
        with pytest.raises(ControlError, match=r"no motor at place 4 \(places 1-3\)"):
            control.execute("plug #4")
        with pytest.raises(ControlError, match="usage: unplug #N"):
            control.execute("unplug #x")
    finally:
        control.close()
        server.stop()
