"""bench/emulator_*: the write-to-read delays are matched to the right reads, and the goal says
what it says (the figures themselves are the bench's, not the tests')."""

from __future__ import annotations

import importlib
import sys
from typing import Any

import pytest

from bench.emulator_bench import _latencies
from bench.emulator_report import (
    BASELINE,
    THIS,
    bare_table,
    goal_met,
    loss_table,
    lost_syncs,
    percentile,
)
from bench.registry import BENCH_DIR


def test_each_ping_is_matched_to_the_read_of_its_last_byte() -> None:
    ping = {"writes": [1.0, 2.0, 3.0], "size": 10}
    # the first PING read whole, the second split in two reads, the third joined with nothing
    stamps = [[1.000050, 10], [2.000010, 4], [2.000100, 6], [3.000200, 10]]
    assert _latencies(ping, stamps) == [50.0, 100.0, 200.0]


def test_a_ping_never_read_ends_the_list() -> None:
    ping = {"writes": [1.0, 2.0], "size": 10}
    assert _latencies(ping, [[1.0001, 10]]) == [100.0]
    assert _latencies({}, []) == []


def test_two_pings_read_together_get_the_same_read_time() -> None:
    ping = {"writes": [1.0, 1.001], "size": 10}
    assert _latencies(ping, [[1.002, 20]]) == [2000.0, 1000.0]


def _session(tree: str, mode: str, lost: int) -> dict[str, Any]:
    return {"tree": tree, "mode": mode, "pypot": {"lost": lost, "writes": 1800}}


def test_the_goal_needs_every_round_at_most_one_lost_and_no_more_than_the_baseline() -> None:
    raw = {"ids": 6, "sessions": [_session(THIS, "a", 6), _session(BASELINE, "a", 12)]}
    assert goal_met(raw) is True
    raw["sessions"].append(_session(THIS, "b", 12))  # two SYNC_WRITEs lost in a round
    assert goal_met(raw) is False
    raw = {"ids": 6, "sessions": [_session(THIS, "a", 6), _session(BASELINE, "a", 0)]}
    assert goal_met(raw) is False  # more than the baseline lost in the same rounds
    assert goal_met({"ids": 6, "sessions": [{"tree": THIS, "mode": "a"}]}) is None


def test_lost_writes_count_in_sync_writes_and_a_failed_client_counts_none() -> None:
    assert lost_syncs({"lost": 12}, 6) == 2
    assert lost_syncs({"error": "import failed"}, 6) is None
    assert percentile([3.0, 1.0, 2.0], 0.5) == 2.0
    assert percentile([], 0.99) == 0.0


def test_the_bare_pty_row_shows_the_kernel_workers_delay_against_the_gap() -> None:
    raw = {
        "bare_pty": [
            {
                "rep": 0,
                "reader": "none",
                "gap_us": 15.0,
                "count": 1000,
                "lost": 94,
                "moved_us": {"p50": 12.1, "p99": 9896.9, "over_gap": 361},
                "load1": 13.8,
            },
            {"rep": 0, "reader": "process", "gap_us": 15.0, "count": 1000, "lost": 35, "load1": 1},
        ]
    }
    rows = bare_table(raw).rows
    assert rows[0][2:5] == ["15 µs", "94 of 1000", "12.1 / 9896.9 µs, 361 of 1000"]
    assert rows[1][4] == "-"  # the worker is timed with nobody reading only


def test_the_loss_row_shows_pypots_own_gap_from_write_to_flush() -> None:
    pypot = {"lost": 12, "writes": 1800, "gap_us": {"p50": 15.3, "p95": 30.0}}
    session = {"tree": THIS, "mode": "a", "rep": 0, "load1": 2.0, "pypot": pypot}
    raw = {"ids": 6, "cycles": 150, "baseline": None, "sessions": [session]}
    row = loss_table(raw).rows[0]
    assert row[3] == "2" and "15.3 µs" in row


class _FakePort:
    def __init__(self) -> None:
        self.calls: list[str] = []

    def write(self, data: bytes) -> int:
        self.calls.append("write")
        return len(data)

    def flushOutput(self) -> None:
        self.calls.append("flush")


def test_pypots_gap_is_timed_from_a_sync_write_to_the_next_flush_only(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.syspath_prepend(str(BENCH_DIR / "peers"))
    torque = importlib.import_module("pypot_torque")
    for name in ("pypot_torque", "_common"):  # the peers' own modules: not left for others
        sys.modules.pop(name, None)
    port = _FakePort()
    stamps = torque.GapStamps(port, 2)
    sync_write = bytes([0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x09, 0x00, 0x83, 0x18, 0x00, 0x01, 0x00])
    read = bytes([0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x07, 0x00, 0x02, 0x18, 0x00, 0x01, 0x00])
    port.flushOutput()  # nothing written yet: no gap
    port.write(sync_write)
    port.flushOutput()  # one gap
    port.write(read)
    port.flushOutput()  # after a READ: no gap (a reply follows it)
    assert port.calls == ["flush", "write", "flush", "write", "flush"]
    assert len(stamps.gaps_us) == 1 and stamps.gaps_us[0] >= 0
    assert set(stamps.summary()) == {"p50", "p95"}
    protocol_1 = torque.GapStamps(_FakePort(), 1)
    assert protocol_1.summary() == {}
