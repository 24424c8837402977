"""Scanning and find_port against the emulator (with wire timing where speed matters)."""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING

import pytest

from poppy_core.bus import FoundMotor, ScanProgress, find_port, scan
from poppy_core.errors import PortError, SetupError

if TYPE_CHECKING:
    from tests.helpers.bus import Emulate


def _ids(found: list[FoundMotor]) -> list[tuple[int, str | None, int, int]]:
    return sorted((f.id, f.model, f.baudrate, f.protocol) for f in found)


def test_scan_finds_exactly_the_emulated_motors_at_their_rate(emulate: Emulate) -> None:
    with emulate("MX-28:11-13,AX-12A:36", baudrate=57_600) as (_, url):
        found = scan(url, [1_000_000, 57_600, 115_200], [1, 2])
    assert _ids(found) == [
        (11, "MX-28", 57_600, 1),
        (12, "MX-28", 57_600, 1),
        (13, "MX-28", 57_600, 1),
        (36, "AX-12A", 57_600, 1),
    ]
    assert all(f.model_number in (12, 29) and f.firmware is not None for f in found)


def test_scan_protocol_2_uses_the_broadcast_ping(emulate: Emulate) -> None:
    with emulate("XL430-W250:1-3,XL-320:7", protocol=2, baudrate=57_600) as (virtual, url):
        progress: list[ScanProgress] = []
        found = scan(url, [1_000_000, 57_600], [2], progress=progress.append)
        assert _ids(found) == [
            (1, "XL430-W250", 57_600, 2),
            (2, "XL430-W250", 57_600, 2),
            (3, "XL430-W250", 57_600, 2),
            (7, "XL-320", 57_600, 2),
        ]
        # Two agreeing broadcast pings per rate and no per-ID ping: the line was clean; one
        # more broadcast confirms the motors found once the line settled.
        assert [p.step for p in progress] == ["broadcast ping", "broadcast ping"]
        assert progress[-1].fraction == 1.0
        assert virtual.packets_received == 5


def test_scan_without_broadcast_pings_each_id(emulate: Emulate) -> None:
    with emulate("XL430-W250:4", protocol=2) as (_, url):
        seen: list[ScanProgress] = []
        found = scan(url, [1_000_000], [2], ids=range(10), broadcast=False, progress=seen.append)
    assert [f.id for f in found] == [4]
    assert [p.id for p in seen] == list(range(10))
    assert seen[-1].found == 1


@pytest.mark.parametrize(("spec", "protocol"), [("AX-12A:1-3", 1), ("XL-320:1-3", 2)])
def test_a_scan_finds_motors_whose_replies_a_busy_machine_makes_late(
    emulate: Emulate, spec: str, protocol: int
) -> None:
    # Every reply 0.1 s late (an emulator, or a Pi, too busy to answer on time), past the
    # scan's waits at a rate and its quiet time after: nothing answered in time, and the
    # patient look at 1 Mbps (find.patient_steps, as find_bus) finds the motors rather than
    # calling an empty bus.
    with emulate(spec, protocol=protocol) as (virtual, url):
        virtual.extra_delay_s = 0.1
        progress: list[ScanProgress] = []
        found = scan(url, [1_000_000], [protocol], ids=range(8), progress=progress.append)
    assert _ids(found) == [(i, spec.split(":")[0], 1_000_000, protocol) for i in (1, 2, 3)]
    assert progress[-1].fraction == 1.0


def test_a_scan_told_not_to_be_patient_does_not_look_again(emulate: Emulate) -> None:
    # A caller trying rates one call at a time (guided setup, protocol 1) is patient once:
    # an impatient call does not look again, so it misses replies a busy machine made late.
    with emulate("AX-12A:1-3", protocol=1) as (virtual, url):
        virtual.extra_delay_s = 0.1
        progress: list[ScanProgress] = []
        found = scan(url, [1_000_000], [1], ids=range(8), progress=progress.append, patient=False)
    assert found == []
    assert progress[-1].total == 8  # one pass over the IDs, no patient look added


def test_scan_reports_unknown_model_numbers(emulate: Emulate) -> None:
    with emulate("MX-28:5") as (virtual, url):
        virtual.motor(5).table.set("model_number", 4242)
        found = scan(url, [1_000_000], [1], ids=range(8))
    assert [(f.id, f.model_number, f.model) for f in found] == [(5, 4242, None)]


def test_scan_abort_and_on_found(emulate: Emulate) -> None:
    with emulate("MX-28:2,MX-28:40") as (_, url):
        calls: list[ScanProgress] = []
        hits: list[FoundMotor] = []

        def progress(p: ScanProgress) -> None:
            calls.append(p)

        found = scan(
            url,
            [1_000_000],
            [1],
            progress=progress,
            on_found=hits.append,
            should_abort=lambda: len(calls) >= 10,
        )
    assert [f.id for f in found] == [2]
    assert hits == found
    assert len(calls) == 10


def test_scan_at_1mbps_with_wire_timing_finds_every_motor(emulate: Emulate) -> None:
    # How fast: `python -m bench scan` (docs/performance.md), not a bound a busy machine breaks.
    with emulate("MX-28:1-6", wire_timing=True, latency_s=0.001) as (_, url):
        found = scan(url, [1_000_000], [1])
    assert [f.id for f in found] == [1, 2, 3, 4, 5, 6]


def test_scan_over_tcp(emulate: Emulate) -> None:
    with emulate("AX-12A:3", via="tcp") as (_, url):
        found = scan(url, [1_000_000], [1], ids=range(6))
    assert [(f.id, f.model) for f in found] == [(3, "AX-12A")]


def test_scan_missing_single_port_raises() -> None:
    with pytest.raises(PortError):
        scan("/dev/ttyUSB_poppy_missing_1", [1_000_000], [1], ids=range(2))


def test_scan_skips_a_missing_port_among_several(emulate: Emulate) -> None:
    with emulate("MX-28:1") as (_, url):
        found = scan(["/dev/ttyUSB_poppy_missing_2", url], [1_000_000], [1], ids=range(3))
    assert [f.id for f in found] == [1]


def test_find_port(emulate: Emulate) -> None:
    with emulate("XL430-W250:1-3", protocol=2, baudrate=57_600) as (_, url):
        assert find_port([1, 2, 3], ports=[url], baudrates=[1_000_000, 57_600]) == (url, 57_600, 2)
        with pytest.raises(SetupError) as info:
            find_port([1, 9], ports=[url], baudrates=[57_600], protocols=[2])
        assert "closest" in str(info.value) and "has 1" in str(info.value)


def test_find_port_without_ports(monkeypatch: pytest.MonkeyPatch) -> None:
    module = importlib.import_module("poppy_core.bus.find")
    monkeypatch.setattr(module, "list_ports", lambda: [])
    with pytest.raises(PortError):
        find_port([1])


def test_find_port_skips_a_missing_port_and_says_when_none_opens(emulate: Emulate) -> None:
    missing = ["/dev/ttyUSB_poppy_missing_3", "/dev/ttyUSB_poppy_missing_4"]
    with emulate("MX-28:1") as (_, url):
        assert find_port([1], ports=[missing[0], url], baudrates=[1_000_000], protocols=[1]) == (
            url,
            1_000_000,
            1,
        )
    with pytest.raises(PortError, match="no port could be opened"):
        find_port([1], ports=missing, baudrates=[1_000_000], protocols=[1])
