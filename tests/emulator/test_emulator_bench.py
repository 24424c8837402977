"""bench/emulator_*: the write-to-read delays are matched to the right reads, and the goal says
what it says (the figures themselves are the bench's, not the tests')."""

from __future__ import annotations

from typing import Any

from bench.emulator_bench import _latencies
from bench.emulator_report import BASELINE, THIS, goal_met, lost_syncs, percentile


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
