"""`poppy motor` without --baud/--protocol: the port is opened once and searched with few packets.

The command runs in this process against virtual motors on the in-process link, so the test
counts what reaches them: each write on the link is one instruction packet, each open of
``emu://`` one opening of the port.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field

import pytest
from typer.testing import CliRunner

from poppy_cli.main import app
from poppy_core.bus import find_bus
from poppy_core.emulator.link import LinkServer, VirtualLine
from poppy_core.errors import PortError, SetupError
from tests.helpers.bus import emulate_bus


@dataclass
class Counts:
    packets: int = 0
    lines: list[VirtualLine] = field(default_factory=list)

    @property
    def opens(self) -> int:
        return len(self.lines)


@pytest.fixture
def counts(monkeypatch: pytest.MonkeyPatch) -> Iterator[Counts]:
    """Count the instruction packets written on ``emu://`` lines and the lines opened."""
    seen = Counts()
    write, open_line = VirtualLine.write, LinkServer.open

    def counted_write(line: VirtualLine, data: bytes) -> None:
        seen.packets += 1
        write(line, data)

    def counted_open(server: LinkServer, baudrate: int) -> VirtualLine:
        line = open_line(server, baudrate)
        seen.lines.append(line)
        return line

    monkeypatch.setattr(VirtualLine, "write", counted_write)
    monkeypatch.setattr(LinkServer, "open", counted_open)
    yield seen


def _set_goal(spec: str, protocol: int, baudrate: int, motor_id: int) -> str:
    with emulate_bus(spec, protocol=protocol, baudrate=baudrate) as (virtual, url):
        result = CliRunner().invoke(
            app, ["motor", "set", str(motor_id), "goal_position", "30", "--port", url]
        )
        assert result.exit_code == 0, result.output
        assert abs(virtual.motor(motor_id).goal_position_deg - 30) < 0.5
    return result.output


@pytest.mark.parametrize(
    ("spec", "protocol", "motor_id"), [("XL-320:1-6", 2, 3), ("MX-28:11-13", 1, 11)]
)
def test_a_motor_at_1_mbps_is_found_at_the_first_rate(
    counts: Counts, spec: str, protocol: int, motor_id: int
) -> None:
    output = _set_goal(spec, protocol, 1_000_000, motor_id)
    assert f"motor {motor_id}: goal_position" in output
    assert counts.opens == 1
    # search: protocol 1 ping and its retry (for an XL-320), or ping and model read (MX-28),
    # then the confirming ping; the command: ping for the model, write, read back, and a read of
    # torque_enable (a goal to a compliant motor gets a note). Before the rates were searched in
    # the outer loop an XL-320 took 23 packets and two opens.
    assert counts.packets <= 8


@pytest.mark.parametrize(
    ("spec", "protocol", "motor_id"), [("XL-320:1-6", 2, 3), ("MX-28:11-13", 1, 11)]
)
def test_a_motor_at_an_unknown_rate_is_searched_on_one_open_port(
    counts: Counts, spec: str, protocol: int, motor_id: int
) -> None:
    _set_goal(spec, protocol, 115_200, motor_id)
    assert counts.opens == 1
    # 1 Mbps, 57,600 bps, 500-200 kbps (protocol 1 only): two packets per protocol tried, and
    # the command's read of torque_enable (the compliant note)
    assert counts.packets <= 24


def test_find_bus_hands_on_the_open_bus(counts: Counts) -> None:
    with (
        emulate_bus("XL-320:1-6", protocol=2, baudrate=57_600) as (_, url),
        find_bus([1, 6], [url]) as bus,
    ):
        assert (bus.port, bus.baudrate, bus.protocol) == (url, 57_600, 2)
        assert bus.ping(4) is not None
    assert counts.opens == 1
    assert not counts.lines[0].is_open


def test_find_bus_closes_the_port_when_nothing_answers(counts: Counts) -> None:
    with (
        emulate_bus("XL-320:1-6", protocol=2) as (_, url),
        pytest.raises(SetupError, match="no motor 9 answers"),
    ):
        find_bus([9], [url], [1_000_000], [2])
    assert counts.opens == 1
    assert not counts.lines[0].is_open


@pytest.mark.parametrize("late_s", [0.05, 0.1])
def test_a_motor_whose_replies_a_busy_machine_makes_late_is_still_found(late_s: float) -> None:
    # Every reply is late (an emulator, or a Pi, too busy to answer on time): the quick search
    # hears nothing in time, and the patient last look at 1 Mbps finds the motor rather than
    # calling an empty bus.
    with emulate_bus("XL-320:1-6", protocol=2) as (bus, url):
        bus.extra_delay_s = late_s
        with find_bus([3], [url]) as found:
            assert (found.baudrate, found.protocol) == (1_000_000, 2)


def test_a_named_port_that_cannot_open_is_a_port_error() -> None:
    with pytest.raises(PortError, match="no such port"):
        find_bus([3], ["/dev/ttyUSB_poppy_missing_6"])
